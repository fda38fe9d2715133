// The visibility buffer that sphere-compute and sphere-rt write (frame.framebuffer): per pixel the 64-bit
// minimum of floatBits(view depth of the hit) << 32 | particle index, kEmptyPixel where empty; the
// resolve pass (shaders/sphere_resolve.comp.glsl) shades each pixel's winner into the image.
#pragma once

#include <cstdint>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/program.h"

namespace pointrast {

// Records the resolve of a frame (program: "sphere_resolve.comp" with LAYOUT = the particles' layout) over
// `pixels` pixels, then a full barrier. `frame`: the address of the frame's SphereFrame.
void recordSphereResolve(VkCommandBuffer cmd, const gpu::ComputeProgram& resolve, uint64_t frame,
                         uint64_t pixels);

// Of the last frame's visibility buffer of `pixels` words: the view depth (+infinity where empty) and the
// particle index (kNoParticle where empty).
std::vector<float> readVisibilityDepth(gpu::Context& context, const gpu::Buffer& framebuffer,
                                       uint64_t pixels);
std::vector<uint32_t> readVisibilityIndices(gpu::Context& context, const gpu::Buffer& framebuffer,
                                            uint64_t pixels);

} // namespace pointrast
