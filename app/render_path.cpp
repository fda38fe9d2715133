#include "render_path.h"

#include <cmath>
#include <cstdio>
#include <memory>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "cli_util.h"
#include "gpu/context.h"
#include "io/media/video_writer.h"
#include "io/output_check.h"
#include "view/path_render.h"

namespace pointrast::app {

void addPathOptions(CLI::App& render, PathOutput& out) {
  render.add_option("--path", out.path,
                    "Render a camera path (JSON keyframes, saved by `pointrast view` with K) into --video or "
                    "--frames-dir instead of one PNG; `orbit`: one turn around the target (of --eye/--target "
                    "or the overview) in 5 s");
  render.add_option("--video", out.video, "--path: the video to write (.mp4 or .mkv, H.264 through ffmpeg)");
  render.add_option("--frames-dir", out.framesDir,
                    "--path: write numbered PNG frames (frame_000000.png, ...) into this folder");
  render.add_option("--fps", out.fps, "--path: frames per second of the path")->capture_default_str();
  render.add_option("--crf", out.crf, "--path --video: H.264 constant rate factor (0 lossless .. 51)")
      ->capture_default_str();
}

view::CameraPath loadPathForRender(const PathOutput& out, uint32_t width, uint32_t height) {
  if (out.video.empty() == out.framesDir.empty())
    throw InputError("--path needs exactly one of --video out.mp4 and --frames-dir DIR");
  if (!(out.fps > 0 && out.fps <= 1000) || !std::isfinite(out.fps))
    throw InputError("--fps must be between 0 and 1000");
  if (out.crf > 51) throw InputError("--crf must be between 0 and 51");
  if (!out.video.empty()) {
    io::videoContainer(out.video); // throws for another extension, before the cloud is loaded
    io::checkOutputTarget(out.video, "--video");
    if (width % 2 || height % 2)
      throw InputError("--video needs an even --width and --height (H.264 halves the color resolution)");
  }
  // The turntable is built once the camera is known (renderCameraPath's caller).
  if (out.path == view::kOrbitPathName) return {};
  return view::CameraPath::load(out.path);
}

int renderCameraPath(gpu::Context& context, Renderer& renderer, std::span<const GpuScene* const> scenes,
                     const RenderSettings& settings, const view::CameraPath& path, const PathOutput& out,
                     bool json, bool quiet, const view::FrameOverlay& overlay) {
  std::unique_ptr<view::FrameSink> sink;
  if (!out.video.empty()) {
    io::VideoOptions options;
    options.width = renderer.width();
    options.height = renderer.height();
    options.fps = out.fps;
    options.crf = out.crf;
    sink = std::make_unique<view::VideoFrameSink>(std::make_unique<io::VideoWriter>(out.video, options));
  } else {
    sink = std::make_unique<view::PngFrameSink>(out.framesDir, renderer.width(), renderer.height());
  }
  view::PathRenderResult result =
      view::renderPath(renderer, scenes, path, out.fps, settings, *sink, !quiet && Progress::enabled(), overlay);
  if (context.validationErrors() > 0)
    throw InputError("the Vulkan validation layer reported " + std::to_string(context.validationErrors()) +
                     " error(s)");
  const std::string& output = out.video.empty() ? out.framesDir : out.video;
  if (json) {
    nlohmann::json j;
    j["device"] = context.info().name;
    j["device_type"] = context.info().typeName;
    j["method"] = methodName(settings.method);
    j["width"] = renderer.width();
    j["height"] = renderer.height();
    j["fps"] = out.fps;
    j["frames"] = result.frames;
    j["seconds"] = result.seconds;
    j["frames_per_second"] = result.framesPerSecond;
    j["median_render_ms"] = result.medianRenderMs;
    j["output"] = output;
    std::printf("%s\n", jsonText(j).c_str());
  } else if (!quiet) {
    std::printf(
        "%s: %llu frames, %ux%u at %g fps, %s: rendered and written in %.2f s (%.1f frames/s; %.3f ms "
        "median GPU time a frame)\n",
        output.c_str(), static_cast<unsigned long long>(result.frames), renderer.width(), renderer.height(),
        out.fps, methodName(settings.method), result.seconds, result.framesPerSecond, result.medianRenderMs);
  }
  return 0;
}

} // namespace pointrast::app
