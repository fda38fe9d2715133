#include "view/path_render.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>

#include "base/error.h"
#include "base/progress.h"
#include "gpu/timer.h"
#include "io/media/video_writer.h"
#include "io/writer.h"

namespace pointrast::view {

namespace {

// Frames waiting for the writer: enough to ride out jitter, few enough to bound memory (3 x 33 MB at 4K).
constexpr size_t kQueuedFrames = 3;

// A bounded queue between the render loop and the writer thread; the first error of either side stops both.
class FrameQueue {
public:
  void push(std::vector<uint32_t>&& frame) {
    std::unique_lock lock(mutex_);
    space_.wait(lock, [&] { return frames_.size() < kQueuedFrames || error_; });
    if (error_) std::rethrow_exception(error_);
    frames_.push_back(std::move(frame));
    ready_.notify_one();
  }
  // False once closed and drained.
  bool pop(std::vector<uint32_t>& frame) {
    std::unique_lock lock(mutex_);
    ready_.wait(lock, [&] { return !frames_.empty() || closed_; });
    if (frames_.empty()) return false;
    frame = std::move(frames_.front());
    frames_.pop_front();
    space_.notify_one();
    return true;
  }
  void close() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    ready_.notify_all();
  }
  void fail(std::exception_ptr error) {
    std::lock_guard lock(mutex_);
    if (!error_) error_ = error;
    frames_.clear();
    space_.notify_all();
  }
  std::exception_ptr error() {
    std::lock_guard lock(mutex_);
    return error_;
  }

private:
  std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<std::vector<uint32_t>> frames_;
  bool closed_ = false;
  std::exception_ptr error_;
};

} // namespace

PngFrameSink::PngFrameSink(std::filesystem::path folder, uint32_t width, uint32_t height)
    : folder_(std::move(folder)), width_(width), height_(height),
      threads_(std::max(1u, std::thread::hardware_concurrency())) {
  std::error_code error;
  std::filesystem::create_directories(folder_, error);
  if (!std::filesystem::is_directory(folder_))
    throw InputError(folder_.string() + ": cannot create the frames folder");
}

std::filesystem::path PngFrameSink::frameName(const std::filesystem::path& folder, uint64_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06llu.png", static_cast<unsigned long long>(index));
  return folder / name;
}

PngFrameSink::~PngFrameSink() {
  // An unfinished render (an error): let the frames in flight end; their errors no longer matter.
  for (std::future<void>& f : pending_)
    if (f.valid()) f.wait();
}

void PngFrameSink::write(uint64_t index, const std::vector<uint32_t>& rgba) {
  if (pending_.size() >= threads_) {
    pending_.front().get(); // rethrows a write error
    pending_.pop_front();
  }
  pending_.push_back(std::async(std::launch::async, [this, index, frame = rgba] {
    io::writePng(frameName(folder_, index), width_, height_, frame.data());
  }));
}

void PngFrameSink::finish() {
  while (!pending_.empty()) {
    pending_.front().get();
    pending_.pop_front();
  }
}

VideoFrameSink::VideoFrameSink(std::unique_ptr<io::VideoWriter> writer) : writer_(std::move(writer)) {}
VideoFrameSink::~VideoFrameSink() = default;

void VideoFrameSink::write(uint64_t, const std::vector<uint32_t>& rgba) {
  writer_->write(rgba.data());
}

void VideoFrameSink::finish() {
  writer_->finish();
}

PathRenderResult renderPath(Renderer& renderer, std::span<const GpuScene* const> scenes,
                            const CameraPath& path, double fps, const RenderSettings& settings,
                            FrameSink& sink, bool progress, const FrameOverlay& overlay) {
  assert(!path.empty() && fps > 0);
  uint64_t frames = path.frameCount(fps);
  auto start = std::chrono::steady_clock::now();
  Progress bar("rendering the path", frames, " frames", progress);
  FrameQueue queue;
  std::thread writer([&] {
    try {
      std::vector<uint32_t> frame;
      for (uint64_t i = 0; queue.pop(frame); ++i) {
        sink.write(i, frame);
        bar.advance(1);
      }
    } catch (...) {
      queue.fail(std::current_exception());
    }
  });
  RenderSettings one = settings;
  one.frames = 1;
  one.warmup = 0;
  std::vector<double> gpuMs;
  try {
    for (uint64_t i = 0; i < frames; ++i) {
      const Camera camera = path.sample(double(i) / fps);
      FrameStats stats = renderer.render(scenes, camera, one);
      gpuMs.push_back(stats.medianMs);
      std::vector<uint32_t> image = renderer.image();
      if (overlay) overlay(camera, image);
      queue.push(std::move(image));
    }
  } catch (...) {
    queue.fail(std::current_exception());
  }
  queue.close();
  writer.join();
  if (std::exception_ptr error = queue.error()) std::rethrow_exception(error);
  sink.finish();
  bar.finish();
  PathRenderResult result;
  result.frames = frames;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.medianRenderMs = gpu::median(gpuMs);
  result.framesPerSecond = result.seconds > 0 ? double(frames) / result.seconds : 0;
  return result;
}

} // namespace pointrast::view
