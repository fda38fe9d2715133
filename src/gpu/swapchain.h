// A swapchain on a window surface (the surface comes from the window library), for the viewer. Images are
// drawn into as color attachments with dynamic rendering; the format is an 8-bit UNORM one (BGRA8 on
// lavapipe and most desktops, RGBA8 elsewhere) so that the renderer's RGBA8 bytes arrive unchanged, never
// an sRGB one, which would re-encode them.
//
//   Swapchain swapchain(context, surface, width, height, /*vsync=*/true);
//   if (auto image = swapchain.acquire()) { ...draw into swapchain.view(*image)...;
//   swapchain.present(*image); }
//   // nullopt or false: out of date (a resize); call recreate(width, height).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "gpu/vulkan_api.h"

namespace pointrast::gpu {

class Context;

class Swapchain {
public:
  // Takes ownership of the surface. Throws UnsupportedError when the device's queue cannot present to it
  // or it offers no 8-bit UNORM format.
  Swapchain(Context& context, VkSurfaceKHR surface, uint32_t width, uint32_t height, bool vsync);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  // Rebuilds the images for a new window size (in pixels); a zero size (minimized) keeps the old ones.
  void recreate(uint32_t width, uint32_t height);

  // The next image's index, with acquired() signalled when it may be drawn; nullopt when the swapchain is
  // out of date.
  std::optional<uint32_t> acquire();
  // The semaphore acquire() signals, and the one a submission drawing image `index` must signal for
  // present() to wait on.
  VkSemaphore acquired() const { return acquired_; }
  VkSemaphore rendered(uint32_t index) const { return rendered_[index]; }
  // Queues the image for display; false when the swapchain is out of date or suboptimal (recreate it).
  bool present(uint32_t index);

  VkImage image(uint32_t index) const { return images_[index]; }
  VkImageView view(uint32_t index) const { return views_[index]; }
  VkFormat format() const { return format_; }
  uint32_t width() const { return extent_.width; }
  uint32_t height() const { return extent_.height; }
  VkPresentModeKHR presentMode() const { return presentMode_; }

private:
  void create(uint32_t width, uint32_t height);
  void destroyImages();
  Context& context_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkColorSpaceKHR colorSpace_ = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  VkPresentModeKHR presentMode_ = VK_PRESENT_MODE_FIFO_KHR;
  VkExtent2D extent_{0, 0};
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  // One "rendered" semaphore per image: a semaphore a present waits on may only be reused once that
  // image was acquired again, which a per-image semaphore guarantees.
  std::vector<VkSemaphore> rendered_;
  VkSemaphore acquired_ = VK_NULL_HANDLE;
};

} // namespace pointrast::gpu
