#include "render/spheres/sphere_visibility.h"

#include <bit>
#include <limits>

#include "gpu/context.h"
#include "gpu/shared_types.h"
#include "render/spheres/sphere_method.h"

namespace pointrast {

namespace {

std::vector<uint64_t> readWords(gpu::Context& context, const gpu::Buffer& framebuffer, uint64_t pixels) {
  std::vector<uint64_t> words(pixels);
  gpu::readBuffer(context, framebuffer, 0, words.data(), words.size() * 8);
  return words;
}

} // namespace

void recordSphereResolve(VkCommandBuffer cmd, const gpu::ComputeProgram& resolve, uint64_t frame,
                         uint64_t pixels) {
  gpu::Grid grid = gpu::gridFor(pixels, resolve.groupSize());
  shared::SpherePush push{};
  push.frame = frame;
  push.groupsX = grid.x;
  resolve.dispatch(cmd, grid.x, grid.y, push);
  gpu::fullBarrier(cmd);
}

std::vector<float> readVisibilityDepth(gpu::Context& context, const gpu::Buffer& framebuffer,
                                       uint64_t pixels) {
  std::vector<uint64_t> words = readWords(context, framebuffer, pixels);
  std::vector<float> depth(words.size());
  for (size_t i = 0; i < words.size(); ++i)
    depth[i] = words[i] == shared::kEmptyPixel ? std::numeric_limits<float>::infinity()
                                               : std::bit_cast<float>(uint32_t(words[i] >> 32));
  return depth;
}

std::vector<uint32_t> readVisibilityIndices(gpu::Context& context, const gpu::Buffer& framebuffer,
                                            uint64_t pixels) {
  std::vector<uint64_t> words = readWords(context, framebuffer, pixels);
  std::vector<uint32_t> index(words.size());
  for (size_t i = 0; i < words.size(); ++i)
    index[i] = words[i] == shared::kEmptyPixel ? kNoParticle : uint32_t(words[i]);
  return index;
}

} // namespace pointrast
