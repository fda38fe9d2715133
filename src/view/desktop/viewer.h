// The desktop viewer: a GLFW window with a Vulkan swapchain showing the session's frames, navigation by
// mouse and keys, and a Dear ImGui panel. One function for app/ to call.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "render/camera.h"
#include "view/frame_log.h"
#include "view/scene_source.h"
#include "view/session.h"

namespace pointrast::view {

class Flight;

struct ViewerOptions {
  uint32_t width = 1280, height = 720; // the window's initial size in pixels
  bool vsync = true;
  bool panel = true;
  // One JSON object a line on stdout for every frame shown and every action (picks, screenshots,
  // keyframes, the exit), for scripts and tests that drive the viewer.
  bool events = false;
  std::optional<Camera> camera; // starting camera; the overview when absent
  double fovY = 60;             // of the overview
  ViewSettings settings;           // settings.method is ignored: `method` below chooses
  std::optional<Method> method;    // absent: defaultMethod() for the input and the device
  std::filesystem::path pathFile = "path.json"; // keyframes: loaded when it exists, saved on every K
  std::filesystem::path screenshotDir = ".";    // F12 writes pointrast-NNNN.png here
  // --annotations: measurements loaded at the start when the file exists, written by Ctrl+S and the
  // panel's Save; empty: measurements are not saved.
  std::filesystem::path annotationsFile;
  // The input as given: the panel's Export LAS reads it when it is a LAS, LAZ or COPC file.
  std::filesystem::path inputFile;
  std::optional<uint32_t> device;
  std::string title = "pointrast";
  // When set, receives every frame rendered and the device, for the statistics written at the close.
  FrameLog* frameLog = nullptr;
  // When set, the viewer plays this flight (flight.h) from its first frame, reports each frame shown to
  // it, and closes when the flight is done.
  Flight* flight = nullptr;
  // How the input goes on the device (default: makeSceneSource); a distributed viewer's rank 0 draws
  // its share and composites every rank's (docs/mpi.md).
  std::function<std::unique_ptr<SceneSource>(gpu::Context&, SceneInput&, const ViewSettings&)> makeSource;
};

// Whether a display is there to open a window on: X11 (DISPLAY) or Wayland (WAYLAND_DISPLAY).
bool hasDisplay();

// Runs the viewer on the input (a cloud uploaded whole or an octree streamed, scene_source.h) until the
// window is closed or Escape is pressed. Returns the exit code (1 when the validation layer reported
// errors). Throws UnsupportedError without GLFW, a display or a presenting device, InputError for bad
// options.
int runViewer(SceneInput& input, const ViewerOptions& options);

} // namespace pointrast::view
