// The resolve stage (shared.h, "The resolve stage"): records its passes after a method's frame. It reads
// one float-depth word per pixel and writes the RGBA8 image, so one copy serves every point method; a
// view is any window of strided buffers, so a stereo renderer runs it once per eye.
#pragma once

#include <cstdint>
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

class PostStage {
public:
  explicit PostStage(gpu::Context& context);
  ~PostStage();

  // Records the passes `settings` ask for, each followed by a full barrier. With `timestamps`, spans
  // firstSpan .. firstSpan + kPostPasses - 1 are written (empty for passes not run). Settings must have
  // passed validatePostSettings().
  void record(VkCommandBuffer cmd, const PostView& view, const PostSettings& settings,
              gpu::TimestampPool* timestamps = nullptr, uint32_t firstSpan = 0);

  // Medians per pass of spans written by record() for `frames` frames, frame f at firstSpan f * kPostPasses.
  static PostStats stats(const std::vector<double>& spanMs, uint32_t frames);

private:
  gpu::Buffer& scratch(int index, uint64_t pixels);
  // AXIS 0..2 gather (post_splat.comp), 3 scatters.
  const gpu::ComputeProgram& splat(bool disc, bool attenuated, uint32_t axis);
  gpu::Context& context_;
  gpu::ComputeProgram splat_[2][2][4]; // [disc][attenuated][axis or scatter], made on first use
  gpu::ComputeProgram dilate_;
  gpu::ComputeProgram compose_;
  gpu::Buffer scratch_[2]; // ping-pong words, width x height each
};

} // namespace pointrast
