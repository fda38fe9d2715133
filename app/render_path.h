// `pointrast render INPUT --path path.json --video out.mp4 | --frames-dir DIR`: a camera path rendered
// headless into a video or numbered PNG frames.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "render/renderer.h"
#include "view/camera_path.h"
#include "view/path_render.h"

namespace CLI {
class App;
}
namespace pointrast::gpu {
class Context;
}

namespace pointrast::app {

struct PathOutput {
  std::string path;      // the camera path file (--path)
  std::string video;     // --video out.mp4
  std::string framesDir; // --frames-dir DIR
  double fps = 60;
  uint32_t crf = 18;
};

// Registers --path, --video, --frames-dir, --fps and --crf on the render command.
void addPathOptions(CLI::App& render, PathOutput& out);

// Checks the options before anything is loaded (exactly one of --video and --frames-dir, an even size for
// video, a sensible frame rate) and loads the path; an empty path for `orbit`, which the caller makes
// with view::orbitPath once it has the camera. Throws InputError.
view::CameraPath loadPathForRender(const PathOutput& out, uint32_t width, uint32_t height);

// Renders every frame of the path and writes the video or the frames; prints a summary line (or one JSON
// object); `overlay`, when set, draws over each frame. Returns the exit code.
int renderCameraPath(gpu::Context& context, Renderer& renderer, std::span<const GpuScene* const> scenes,
                     const RenderSettings& settings, const view::CameraPath& path, const PathOutput& out,
                     bool json, bool quiet, const view::FrameOverlay& overlay = {});

} // namespace pointrast::app
