#include "render/spheres/sphere_attachments.h"

#include <cstring>
#include <limits>

#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/graphics.h"

namespace pointrast {

namespace {

constexpr VkPipelineStageFlags2 kDepthStages =
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
constexpr VkAccessFlags2 kDepthAccess =
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;

const gpu::ImageUse kColorAttachment{VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
const gpu::ImageUse kDepthAttachment{kDepthStages, kDepthAccess, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL};
const gpu::ImageUse kCopySource{VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                                VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};

} // namespace

SphereAttachments::SphereAttachments(gpu::Context& context, uint32_t width, uint32_t height)
    : context_(context),
      color_(context, width, height, kColorFormat,
             VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "sphere color"),
      index_(context, width, height, kIndexFormat,
             VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "sphere particle index"),
      depth_(context, width, height, kDepthFormat,
             VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "sphere depth") {}

gpu::GraphicsOptions SphereAttachments::pipelineOptions(uint32_t layout, const SphereSettings& settings) {
  const uint32_t billboard = settings.billboard == SphereBillboard::Camera ? shared::kSphereBillboardCamera
                                                                           : shared::kSphereBillboardScreen;
  gpu::GraphicsOptions options;
  options.colorFormat = kColorFormat;
  options.depthFormat = kDepthFormat;
  options.depthCompare = VK_COMPARE_OP_GREATER; // reverse-Z
  options.secondColorFormat = kIndexFormat;
  options.conservative = settings.conservative;
  options.spec = {{/* LAYOUT= */ 0, layout}, {/* BILLBOARD= */ 2, billboard}};
  return options;
}

void SphereAttachments::begin(VkCommandBuffer cmd, uint32_t background) {
  // Every attachment is cleared on load: old contents are discarded (UNDEFINED). The color image waits
  // for the previous frame's copy out of it, the others for the previous frame's writes and readbacks.
  gpu::imageBarrier(cmd, color_, {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE, VK_IMAGE_LAYOUT_UNDEFINED},
                    kColorAttachment);
  gpu::imageBarrier(cmd, index_,
                    {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_2_COPY_BIT,
                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED},
                    kColorAttachment);
  gpu::imageBarrier(cmd, depth_,
                    {kDepthStages | VK_PIPELINE_STAGE_2_COPY_BIT,
                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED},
                    kDepthAttachment);

  VkRenderingAttachmentInfo colors[2] = {{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO},
                                         {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO}};
  colors[0].imageView = color_.view();
  colors[0].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  colors[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  colors[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  // k / 255 converts back to exactly k in a UNORM attachment (round to nearest).
  for (int c = 0; c < 4; ++c)
    colors[0].clearValue.color.float32[c] = float((background >> (8 * c)) & 0xFFu) / 255.0f;
  colors[1] = colors[0];
  colors[1].imageView = index_.view();
  colors[1].clearValue.color.uint32[0] = kNoParticle;
  VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  depth.imageView = depth_.view();
  depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
  depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE; // read back by depth()
  depth.clearValue.depthStencil = {0.0f, 0};    // reverse-Z: 0 is infinitely far
  VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
  rendering.renderArea = {{0, 0}, {color_.width(), color_.height()}};
  rendering.layerCount = 1;
  rendering.colorAttachmentCount = 2;
  rendering.pColorAttachments = colors;
  rendering.pDepthAttachment = &depth;
  gpu::vkCmdBeginRendering(cmd, &rendering);
  gpu::setViewport(cmd, color_.width(), color_.height());
}

void SphereAttachments::end(VkCommandBuffer cmd, SphereTargets& targets) {
  gpu::vkCmdEndRendering(cmd);
  gpu::imageBarrier(cmd, color_, kColorAttachment, kCopySource);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {targets.width, targets.height, 1};
  gpu::vkCmdCopyImageToBuffer(cmd, color_.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                              targets.image.handle(), 1, &region);
  gpu::fullBarrier(cmd);
}

std::vector<float> SphereAttachments::depth(float nearW) {
  std::vector<float> z = read<float>(depth_, true);
  for (float& d : z)
    d = d > 0 ? nearW / d : std::numeric_limits<float>::infinity();
  return z;
}

std::vector<uint32_t> SphereAttachments::indices() {
  return read<uint32_t>(index_, false);
}

// Copies an attachment of the last frame into host memory and leaves it in its attachment layout.
template <class T> std::vector<T> SphereAttachments::read(const gpu::Image& image, bool depth) {
  gpu::ImageUse use = depth ? kDepthAttachment : kColorAttachment;
  VkImageAspectFlags aspect = depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
  std::vector<T> pixels(uint64_t(image.width()) * image.height());
  gpu::Buffer staging(context_, pixels.size() * sizeof(T), VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                      gpu::MemoryKind::Readback, "attachment readback");
  context_.submitAndWait([&](VkCommandBuffer cmd) {
    gpu::imageBarrier(cmd, image, use, kCopySource);
    VkBufferImageCopy region{};
    region.imageSubresource = {aspect, 0, 0, 1};
    region.imageExtent = {image.width(), image.height(), 1};
    gpu::vkCmdCopyImageToBuffer(cmd, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.handle(),
                                1, &region);
    gpu::imageBarrier(cmd, image, kCopySource, use);
    gpu::fullBarrier(cmd);
  });
  staging.invalidate();
  std::memcpy(pixels.data(), staging.mapped(), pixels.size() * sizeof(T));
  return pixels;
}

} // namespace pointrast
