// 2D device-local images with one view, for the attachments of graphics pipelines (the compute methods
// need none: their framebuffers are buffers). Layout transitions are the caller's, through imageBarrier.
#pragma once

#include <cstdint>
#include <string>

#include "gpu/vulkan_api.h"

namespace pointrast::gpu {

class Context;

class Image {
public:
  Image() = default;
  // One mip level, one layer, one sample, optimal tiling; the view covers the aspect of the format (color,
  // or depth for depth formats). Throws UnsupportedError when the memory cannot be had.
  Image(Context& context, uint32_t width, uint32_t height, VkFormat format, VkImageUsageFlags usage,
        const std::string& name);
  ~Image();
  Image(Image&& other) noexcept;
  Image& operator=(Image&& other) noexcept;
  Image(const Image&) = delete;
  Image& operator=(const Image&) = delete;

  VkImage handle() const { return image_; }
  VkImageView view() const { return view_; }
  VkFormat format() const { return format_; }
  VkImageAspectFlags aspect() const { return aspect_; }
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  explicit operator bool() const { return image_ != VK_NULL_HANDLE; }

private:
  void release();
  VkDevice device_ = VK_NULL_HANDLE;
  VkImage image_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkImageAspectFlags aspect_ = 0;
  uint32_t width_ = 0, height_ = 0;
};

// One synchronization2 image barrier over the whole image: a layout transition and the dependency between
// the stages/accesses before and after it. oldLayout UNDEFINED discards the contents (cheaper than keeping
// them when the next pass clears anyway).
struct ImageUse {
  VkPipelineStageFlags2 stage;
  VkAccessFlags2 access;
  VkImageLayout layout;
};
void imageBarrier(VkCommandBuffer cmd, const Image& image, ImageUse before, ImageUse after);

} // namespace pointrast::gpu
