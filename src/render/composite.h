// The last step of a sort-last distributed frame (docs/mpi.md): canonical framebuffer words composited
// elsewhere (the MIN over every rank's depth << 32 | color words) become the RGBA8 image, with the colors
// of the words, the background where no point landed, and the resolve stage of the settings (point size,
// dilation, eye-dome lighting) run once, on this device, on the composited frame.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "render/renderer.h"

namespace pointrast {

namespace gpu {
class Buffer;
class Context;
} // namespace gpu
class PostStage;

class CompositeResolver {
public:
  // eyes = 2: words of a stereo frame, both eyes side by side (width is then one eye's).
  CompositeResolver(gpu::Context& context, uint32_t width, uint32_t height, uint32_t eyes = 1);
  ~CompositeResolver();

  // `words`: one canonical word per pixel of the whole image, as Renderer::framebufferWords() returns them
  // for `settings` rendered without the resolve stage (int40 words for DepthMode::Int40, whose steps per
  // unit are `int40Scale`). Returns the image, row 0 at the top; *post receives the stage's GPU times
  // when it ran; *ended the words the frame ended with, as Renderer::framebufferWords() returns them after
  // such a frame (`words` themselves without the resolve stage, its float-depth words with it). Throws
  // InputError for resolve-stage settings out of range.
  std::vector<uint32_t> resolve(std::span<const uint64_t> words, const Camera& camera,
                                const RenderSettings& settings, double int40Scale,
                                std::optional<PostStats>* post = nullptr,
                                std::vector<uint64_t>* ended = nullptr);

private:
  gpu::Context& context_;
  uint32_t width_, height_, eyes_;
  std::unique_ptr<PostStage> post_; // made on the first frame that uses it
  // The resolve stage's buffers, made on its first frame and kept for the next (a viewer resolves every
  // frame): the words uploaded, on the device, the image and what is read back.
  std::unique_ptr<gpu::Buffer> upload_, words_, image_, readback_;
};

// steps per unit of depth of the int40 encoding for these scenes and camera, as the renderer computes it
// when RenderSettings::depthScale is 0.
double int40ScaleOf(std::span<const GpuScene* const> scenes, const Camera& camera);

} // namespace pointrast
