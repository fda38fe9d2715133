#include "gpu/image.h"

#include "gpu/buffer.h"

#include <utility>

#include "base/error.h"
#include "gpu/context.h"

namespace pointrast::gpu {

namespace {

bool isDepthFormat(VkFormat format) {
  switch (format) {
  case VK_FORMAT_D16_UNORM:
  case VK_FORMAT_X8_D24_UNORM_PACK32:
  case VK_FORMAT_D32_SFLOAT:
    return true;
  default:
    return false;
  }
}

} // namespace

Image::Image(Context& context, uint32_t width, uint32_t height, VkFormat format, VkImageUsageFlags usage,
             const std::string& name)
    : device_(context.device()), format_(format),
      aspect_(isDepthFormat(format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT), width_(width),
      height_(height) {
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width, height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VK_CHECK(vkCreateImage(device_, &info, nullptr, &image_));
  try {
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device_, image_, &req);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = [&] { bool coherent; return findMemoryType(context, req.memoryTypeBits, MemoryKind::Device, coherent); }();
    VkResult r = vkAllocateMemory(device_, &alloc, nullptr, &memory_);
    if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
      throw UnsupportedError("out of memory allocating the " + std::to_string(width) + "x" +
                             std::to_string(height) + " image '" + name + "'");
    VK_CHECK(r);
    VK_CHECK(vkBindImageMemory(device_, image_, memory_, 0));
    VkImageViewCreateInfo viewInfo{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    viewInfo.image = image_;
    viewInfo.viewType = VK_IMAGE_VIEW_TYPE_2D;
    viewInfo.format = format;
    viewInfo.subresourceRange = {aspect_, 0, 1, 0, 1};
    VK_CHECK(vkCreateImageView(device_, &viewInfo, nullptr, &view_));
    context.setName(VK_OBJECT_TYPE_IMAGE, uint64_t(image_), name);
    context.setName(VK_OBJECT_TYPE_IMAGE_VIEW, uint64_t(view_), name + " view");
    context.setName(VK_OBJECT_TYPE_DEVICE_MEMORY, uint64_t(memory_), name + " memory");
  } catch (...) {
    release();
    throw;
  }
}

Image::~Image() {
  release();
}

void Image::release() {
  if (deviceFaulted()) return; // the GPU may still use it: leave it to process exit
  if (view_) vkDestroyImageView(device_, view_, nullptr);
  if (image_) vkDestroyImage(device_, image_, nullptr);
  if (memory_) vkFreeMemory(device_, memory_, nullptr);
  view_ = VK_NULL_HANDLE;
  image_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
}

Image::Image(Image&& other) noexcept {
  *this = std::move(other);
}

Image& Image::operator=(Image&& other) noexcept {
  if (this != &other) {
    release();
    device_ = other.device_;
    image_ = std::exchange(other.image_, VK_NULL_HANDLE);
    view_ = std::exchange(other.view_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    format_ = other.format_;
    aspect_ = other.aspect_;
    width_ = other.width_;
    height_ = other.height_;
  }
  return *this;
}

void imageBarrier(VkCommandBuffer cmd, const Image& image, ImageUse before, ImageUse after) {
  VkImageMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  barrier.srcStageMask = before.stage;
  barrier.srcAccessMask = before.access;
  barrier.dstStageMask = after.stage;
  barrier.dstAccessMask = after.access;
  barrier.oldLayout = before.layout;
  barrier.newLayout = after.layout;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image.handle();
  barrier.subresourceRange = {image.aspect(), 0, 1, 0, 1};
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.imageMemoryBarrierCount = 1;
  dep.pImageMemoryBarriers = &barrier;
  vkCmdPipelineBarrier2(cmd, &dep);
}

} // namespace pointrast::gpu
