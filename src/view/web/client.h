// One browser tab on the render thread: its own Session (camera, settings, keyframes) over the shared
// GpuCloud, drawn by its own SceneViews at the canvas size (and a smaller one for frames while the camera
// moves), fed by the validated messages the connection thread hands over, and streamed through its
// FrameStream. Nothing here runs on a network thread; the GPU is touched only from the render thread.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "render/camera.h"
#include "view/motion.h"
#include "view/scene_view.h"
#include "view/session.h"
#include "view/web/protocol.h"
#include "view/web/stream.h"

namespace pointrast::view::web {

// How a client's frames are streamed; the page may change it (a "stream" message).
struct StreamSettings {
  double motionScale = 0.5; // side of the motion frames relative to the canvas
  int quality = 90;         // JPEG quality of the full frame at rest (4:4:4)
  int motionQuality = 60;   // JPEG quality of motion frames (4:2:0, fast DCT)
};

// What every client starts from.
struct ClientSetup {
  gpu::Context* context = nullptr;
  SceneSource* cloud = nullptr;        // the input on the GPU, shared by every client
  std::span<const Method> methods;     // this device runs them
  std::optional<Camera> camera;        // starting camera; the overview when absent
  double fovY = 60;                    // of the overview
  std::span<const glm::dvec3> framing; // the points the overview frames (SceneInput::framing)
  ViewSettings settings;
  Viewport maxSize{3840, 2160}; // frames are at most this large (aspect kept)
  StreamSettings stream;
  Annotations annotations; // --annotations: every client's measurement list starts with them
};

// The canvas size clamped into `maxSize`, aspect kept, at least 1x1.
Viewport clampViewport(uint32_t width, uint32_t height, Viewport maxSize);
// The viewport scaled by `scale` per side (rounded, at least 1x1).
Viewport scaleViewport(Viewport viewport, double scale);

class WebClient {
public:
  WebClient(const ClientSetup& setup, FrameStream& stream);

  // Applies one validated message (acks are the connection's business and never come here).
  void receive(const ClientMessage& message);
  // Serves the session's requests and renders a frame when one is due and the stream takes one. Returns
  // when it must run again without new input (fly keys held, a full frame owed), if ever.
  std::optional<double> step(double now);

  // Nothing to show before the page said how large its canvas is.
  bool started() const { return session_.has_value(); }
  const Session& session() const { return *session_; }

private:
  void resize(uint32_t width, uint32_t height);
  void pointer(const ClientMessage& m);
  void serveRequests();
  void renderFrame(double now, FrameQuality quality);
  void sendScreenshot();
  void sendMeasurements();
  std::string stateJson(const FrameHeader* frame) const;
  glm::dvec2 pixels(glm::dvec2 normalized) const;

  const ClientSetup& setup_;
  FrameStream& stream_;
  std::optional<Session> session_;
  SceneView full_, motion_;
  MotionQuality quality_;
  StreamSettings settings_;
  uint32_t seq_ = 0;       // last input sequence number applied
  uint32_t nextFrame_ = 1; // frame ids start at 1
  double wheel_ = 0;       // steps gathered since the last step(), zoomed at once
  glm::dvec2 wheelAt_{0};
  double lastStep_ = -1;
  // When the oldest input that no frame has shown yet arrived (server clock), and what the last frame
  // reports of it: how long that input waited before the frame's drawing began, and how long drawing the
  // frame took on this thread (upload, render, readback, overlay).
  std::optional<double> inputSince_;
  double inputWaitMs_ = 0, frameWallMs_ = 0;
  bool stateChanged_ = true; // something the panel shows changed without a frame
  // The pick tool's click, served with the other requests: the position and the measurement it extends.
  std::optional<std::pair<glm::dvec2, std::optional<AnnotationKind>>> toolPick_;
  // A vertex dragged with the pick tool: from, to (viewport pixels).
  std::optional<std::pair<glm::dvec2, glm::dvec2>> vertexMove_;
};

} // namespace pointrast::view::web
