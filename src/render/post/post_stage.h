// The resolve stage (shared.h, "The resolve stage"): records its passes after a method's frame. It reads
// one float-depth word per pixel and writes the RGBA8 image, so one copy serves every point method; a
// view is any window of strided buffers, so a stereo renderer runs it once per eye.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/program.h"
#include "render/post/post_settings.h"

namespace pointrast {

namespace gpu {
class Context;
class TimestampPool;
} // namespace gpu

// The pixels one run of the stage works on.
struct PostView {
  uint64_t words = 0; // uint64_t words in (and, with captureWords, the final words out)
  uint64_t image = 0; // RGBA8 out
  uint32_t width = 0, height = 0;
  uint32_t pitch = 0;          // elements per row of words and image (>= width)
  float referenceDepth = 1.0f; // attenuated sizes: the linear depth at which a point is pointSize pixels
  uint32_t background = 0;     // RGBA8
  bool captureWords = false;   // write the final words back into `words`
};

// Passes timed per frame, in order: splat, dilate, compose (PostStats).
constexpr uint32_t kPostPasses = 3;
// Views one run works on: the two eyes of a stereo frame.
constexpr size_t kMaxPostViews = 2;

class PostStage {
public:
  explicit PostStage(gpu::Context& context);
  ~PostStage();

  // Records the passes `settings` ask for, each followed by a full barrier. With `timestamps`, spans
  // firstSpan .. firstSpan + kPostPasses - 1 are written (empty for passes not run). Settings must have
  // passed validatePostSettings().
  void record(VkCommandBuffer cmd, const PostView& view, const PostSettings& settings,
              gpu::TimestampPool* timestamps = nullptr, uint32_t firstSpan = 0);
  // The same for several views of one size (the eyes of a stereo frame), each pass over all of them in
  // one span: the spans time the stage for the whole frame.
  void record(VkCommandBuffer cmd, std::span<const PostView> views, const PostSettings& settings,
              gpu::TimestampPool* timestamps = nullptr, uint32_t firstSpan = 0);

  // Medians per pass of spans written by record() for `frames` frames, frame f at firstSpan f * kPostPasses.
  static PostStats stats(const std::vector<double>& spanMs, uint32_t frames);

private:
  gpu::Buffer& scratch(int index, uint64_t pixels);
  // The variants of post_splat.comp: fixed sizes gathered, attenuated ones scattered.
  enum class Splat { SquareRows, SquareColumns, DiscWindow, SquareScatter, DiscScatter, Count };
  const gpu::ComputeProgram& splat(Splat variant);
  gpu::Context& context_;
  gpu::ComputeProgram splat_[size_t(Splat::Count)]; // made on first use
  gpu::ComputeProgram dilate_;
  gpu::ComputeProgram compose_;
  gpu::Buffer scratch_[2]; // ping-pong words, width x height each
};

} // namespace pointrast
