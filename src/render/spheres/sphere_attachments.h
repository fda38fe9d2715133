// The attachments of a rasterization sphere pipeline and the frame around its draws: RGBA8 color (copied
// into the shared image at the end of a frame), R32_UINT particle index and D32 reverse-Z depth (read back
// for tests), all cleared on load. The rasterization and mesh pipelines (sphere_hardware.cpp,
// sphere_mesh.cpp) draw between begin() and end().
#pragma once

#include <cstdint>
#include <vector>

#include "gpu/graphics.h"
#include "gpu/image.h"
#include "render/spheres/sphere_method.h"

namespace pointrast {

class SphereAttachments {
public:
  static constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM; // byte order r, g, b, a = the image's
  static constexpr VkFormat kIndexFormat = VK_FORMAT_R32_UINT;
  static constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

  SphereAttachments(gpu::Context& context, uint32_t width, uint32_t height);

  // What every pipeline drawing into these attachments sets alike: their formats, the reverse-Z depth test,
  // conservative rasterization as the settings ask, and the specialization constants LAYOUT (0, of every
  // sphere shader) = `layout` and BILLBOARD (2, of the vertex or mesh stage) from the settings.
  static gpu::GraphicsOptions pipelineOptions(uint32_t layout, const SphereSettings& settings);

  // Transitions the attachments (discarding their contents), begins dynamic rendering with color =
  // background, index = kNoParticle, depth = 0 (reverse-Z: infinitely far), and sets viewport and scissor.
  void begin(VkCommandBuffer cmd, uint32_t background);
  // Ends rendering and copies the color attachment into targets.image, then a full barrier.
  void end(VkCommandBuffer cmd, SphereTargets& targets);

  // Of the last frame: the linear view depth (nearW / stored depth; +infinity where empty) and the particle
  // index (kNoParticle where empty).
  std::vector<float> depth(float nearW);
  std::vector<uint32_t> indices();

private:
  template <class T> std::vector<T> read(const gpu::Image& image, bool depth);

  gpu::Context& context_;
  gpu::Image color_, index_, depth_;
};

} // namespace pointrast
