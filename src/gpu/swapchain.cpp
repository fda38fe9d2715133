#include "gpu/swapchain.h"

#include <algorithm>
#include <cassert>
#include <limits>

#include "base/error.h"
#include "gpu/context.h"

namespace pointrast::gpu {

namespace {

// 8-bit UNORM formats in order of preference (lavapipe's swapchain offers BGRA8 only).
constexpr VkFormat kFormats[] = {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM};

VkSurfaceFormatKHR chooseFormat(VkPhysicalDevice physical, VkSurfaceKHR surface) {
  uint32_t count = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(count);
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, formats.data()));
  for (VkFormat wanted : kFormats)
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == wanted && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) return f;
  throw UnsupportedError("the window offers no 8-bit UNORM swapchain format (BGRA8 or RGBA8)");
}

// FIFO (vsync) is the one mode every device has; without vsync, MAILBOX (no tearing) or IMMEDIATE.
VkPresentModeKHR choosePresentMode(VkPhysicalDevice physical, VkSurfaceKHR surface, bool vsync) {
  if (vsync) return VK_PRESENT_MODE_FIFO_KHR;
  uint32_t count = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(physical, surface, &count, nullptr));
  std::vector<VkPresentModeKHR> modes(count);
  VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(physical, surface, &count, modes.data()));
  for (VkPresentModeKHR wanted : {VK_PRESENT_MODE_MAILBOX_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR})
    if (std::find(modes.begin(), modes.end(), wanted) != modes.end()) return wanted;
  return VK_PRESENT_MODE_FIFO_KHR;
}

VkSemaphore createSemaphore(Context& context, const char* name) {
  VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  VkSemaphore semaphore = VK_NULL_HANDLE;
  VK_CHECK(vkCreateSemaphore(context.device(), &info, nullptr, &semaphore));
  context.setName(VK_OBJECT_TYPE_SEMAPHORE, uint64_t(semaphore), name);
  return semaphore;
}

} // namespace

Swapchain::Swapchain(Context& context, VkSurfaceKHR surface, uint32_t width, uint32_t height, bool vsync)
    : context_(context), surface_(surface) {
  assert(context.presenting() && "a Context without ContextOptions::surfaceExtensions");
  try {
    VkBool32 supported = VK_FALSE;
    VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(context.physicalDevice(), context.queueFamily(), surface,
                                                  &supported));
    if (!supported)
      throw UnsupportedError("device '" + context.info().name + "' cannot present to this window");
    VkSurfaceFormatKHR format = chooseFormat(context.physicalDevice(), surface);
    format_ = format.format;
    colorSpace_ = format.colorSpace;
    presentMode_ = choosePresentMode(context.physicalDevice(), surface, vsync);
    acquired_ = createSemaphore(context, "swapchain image acquired");
    create(width, height);
  } catch (...) {
    destroyImages();
    if (acquired_) vkDestroySemaphore(context.device(), acquired_, nullptr);
    vkDestroySurfaceKHR(context.instance(), surface_, nullptr);
    throw;
  }
}

Swapchain::~Swapchain() {
  if (deviceFaulted()) return;
  vkDeviceWaitIdle(context_.device());
  destroyImages();
  if (swapchain_) vkDestroySwapchainKHR(context_.device(), swapchain_, nullptr);
  vkDestroySemaphore(context_.device(), acquired_, nullptr);
  vkDestroySurfaceKHR(context_.instance(), surface_, nullptr);
}

void Swapchain::destroyImages() {
  for (VkImageView view : views_)
    vkDestroyImageView(context_.device(), view, nullptr);
  for (VkSemaphore s : rendered_)
    vkDestroySemaphore(context_.device(), s, nullptr);
  views_.clear();
  rendered_.clear();
  images_.clear();
}

void Swapchain::create(uint32_t width, uint32_t height) {
  VkSurfaceCapabilitiesKHR caps{};
  VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(context_.physicalDevice(), surface_, &caps));
  // The window system fixes the extent unless it says 0xFFFFFFFF (then the window's size, clamped).
  VkExtent2D extent = caps.currentExtent;
  if (extent.width == std::numeric_limits<uint32_t>::max()) {
    extent.width = std::clamp(width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent.height = std::clamp(height, caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  if (extent.width == 0 || extent.height == 0) return; // minimized: keep what there is
  uint32_t imageCount = caps.minImageCount + 1;
  if (caps.maxImageCount > 0) imageCount = std::min(imageCount, caps.maxImageCount);

  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = surface_;
  info.minImageCount = imageCount;
  info.imageFormat = format_;
  info.imageColorSpace = colorSpace_;
  info.imageExtent = extent;
  info.imageArrayLayers = 1;
  info.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                            ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                            : VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha &
                                                          -caps.supportedCompositeAlpha); // lowest bit
  info.presentMode = presentMode_;
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_;
  VkSwapchainKHR created = VK_NULL_HANDLE;
  VK_CHECK(vkCreateSwapchainKHR(context_.device(), &info, nullptr, &created));
  if (swapchain_) vkDestroySwapchainKHR(context_.device(), swapchain_, nullptr);
  swapchain_ = created;
  extent_ = extent;

  destroyImages();
  uint32_t count = 0;
  VK_CHECK(vkGetSwapchainImagesKHR(context_.device(), swapchain_, &count, nullptr));
  images_.resize(count);
  VK_CHECK(vkGetSwapchainImagesKHR(context_.device(), swapchain_, &count, images_.data()));
  for (uint32_t i = 0; i < count; ++i) {
    VkImageViewCreateInfo viewInfo{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    viewInfo.image = images_[i];
    viewInfo.viewType = VK_IMAGE_VIEW_TYPE_2D;
    viewInfo.format = format_;
    viewInfo.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView view = VK_NULL_HANDLE;
    VK_CHECK(vkCreateImageView(context_.device(), &viewInfo, nullptr, &view));
    views_.push_back(view);
    rendered_.push_back(createSemaphore(context_, "swapchain image rendered"));
    context_.setName(VK_OBJECT_TYPE_IMAGE, uint64_t(images_[i]), "swapchain image");
  }
}

void Swapchain::recreate(uint32_t width, uint32_t height) {
  VK_CHECK(vkDeviceWaitIdle(context_.device()));
  create(width, height);
}

std::optional<uint32_t> Swapchain::acquire() {
  if (!swapchain_) return std::nullopt;
  uint32_t index = 0;
  VkResult r = VK_CHECK_ALLOW(
      vkAcquireNextImageKHR(context_.device(), swapchain_, UINT64_MAX, acquired_, VK_NULL_HANDLE, &index),
      VK_SUBOPTIMAL_KHR, VK_ERROR_OUT_OF_DATE_KHR);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) return std::nullopt;
  return index;
}

bool Swapchain::present(uint32_t index) {
  VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  info.waitSemaphoreCount = 1;
  info.pWaitSemaphores = &rendered_[index];
  info.swapchainCount = 1;
  info.pSwapchains = &swapchain_;
  info.pImageIndices = &index;
  VkResult r =
      VK_CHECK_ALLOW(vkQueuePresentKHR(context_.queue(), &info), VK_SUBOPTIMAL_KHR, VK_ERROR_OUT_OF_DATE_KHR);
  return r == VK_SUCCESS;
}

} // namespace pointrast::gpu
