// Draws Dear ImGui's draw lists with the gpu layer's own graphics programs: vertices and indices pulled by
// buffer device address, the font atlas read from a buffer, dynamic rendering. The imgui package's Vulkan
// backend is not used: it calls Vulkan through linked prototypes (a binary with it would need libvulkan at
// link time, where pointrast loads it at run time to say clearly when it is missing) and needs a render
// pass and descriptor sets that the rest of pointrast does without.
#pragma once

#include <cstdint>

#include "gpu/buffer.h"
#include "gpu/graphics.h"

struct ImDrawData;

namespace pointrast::view {

class PanelRenderer {
public:
  // Builds the current ImGui context's font atlas into a buffer. colorFormat: the target's format.
  PanelRenderer(gpu::Context& context, VkFormat colorFormat);

  // The picture ImGui::Image(kImageId, ...) shows: width x height RGBA8 pixels, row 0 at the top, copied.
  // Call between frames (present() waits for its pass, so the previous picture is no longer read).
  static constexpr intptr_t kImageId = 2;
  void setImage(uint32_t width, uint32_t height, const uint32_t* rgba);

  // Uploads the draw lists (before the command buffer is recorded).
  void upload(const ImDrawData& data);
  // Records the draws, inside vkCmdBeginRendering on a width x height target, after upload().
  void record(VkCommandBuffer cmd, const ImDrawData& data, uint32_t width, uint32_t height);

private:
  gpu::Context& context_;
  gpu::GraphicsProgram program_;
  gpu::Buffer font_, vertices_, indices_;
  uint32_t fontWidth_ = 0, fontHeight_ = 0;
  gpu::Buffer image_;
  uint32_t imageWidth_ = 0, imageHeight_ = 0;
};

} // namespace pointrast::view
