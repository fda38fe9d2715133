// Renders a camera path headless, frame by frame, into a sink: a video through ffmpeg or numbered PNG
// files. Rendering and writing overlap: a writer thread takes finished frames from a short queue, so the
// GPU renders frame n + 1 while frame n is encoded. A progress line with the ETA goes to stderr.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <filesystem>
#include <future>
#include <memory>
#include <span>
#include <vector>

#include "render/renderer.h"
#include "view/camera_path.h"

namespace pointrast::io {
class VideoWriter;
}

namespace pointrast::view {

class FrameSink {
public:
  virtual ~FrameSink() = default;
  // Called in frame order from the writer thread; throws to stop the render.
  virtual void write(uint64_t index, const std::vector<uint32_t>& rgba) = 0;
  // After the last frame: makes the output final (renames it into place).
  virtual void finish() = 0;
};

// frame_000000.png, frame_000001.png, ... in a folder (created when missing). Each PNG is complete or
// absent (io::writePng). PNG compression is slower than rendering, so frames are compressed on as many
// threads as the machine has, in any order.
class PngFrameSink : public FrameSink {
public:
  PngFrameSink(std::filesystem::path folder, uint32_t width, uint32_t height);
  ~PngFrameSink() override;
  void write(uint64_t index, const std::vector<uint32_t>& rgba) override;
  void finish() override;
  static std::filesystem::path frameName(const std::filesystem::path& folder, uint64_t index);

private:
  std::filesystem::path folder_;
  uint32_t width_, height_;
  size_t threads_;
  std::deque<std::future<void>> pending_;
};

class VideoFrameSink : public FrameSink {
public:
  explicit VideoFrameSink(std::unique_ptr<io::VideoWriter> writer);
  ~VideoFrameSink() override;
  void write(uint64_t index, const std::vector<uint32_t>& rgba) override;
  void finish() override;

private:
  std::unique_ptr<io::VideoWriter> writer_;
};

// Draws over a frame (RGBA8, the renderer's size) just rendered with the camera, before it is written; the
// renderer still holds the frame (its words, for a depth test).
using FrameOverlay = std::function<void(const Camera&, std::vector<uint32_t>&)>;

struct PathRenderResult {
  uint64_t frames = 0;
  double seconds = 0;         // wall clock of the whole render, writing included
  double medianRenderMs = 0;  // median GPU time of a frame (clear + draw + resolve)
  double framesPerSecond = 0; // frames / seconds: the throughput of the whole pipeline
};

// Renders path.frameCount(fps) frames at the renderer's size and hands them to the sink in order, then
// finishes it, each frame drawn over by `overlay` when set. On any error the sink is not finished (and
// cleans up when destroyed).
PathRenderResult renderPath(Renderer& renderer, std::span<const GpuScene* const> scenes,
                            const CameraPath& path, double fps, const RenderSettings& settings,
                            FrameSink& sink, bool progress, const FrameOverlay& overlay = {});

} // namespace pointrast::view
