#include "view/desktop/presenter.h"

#include <imgui.h>

#include "gpu/context.h"
#include "gpu/shared_types.h"
#include "gpu/swapchain.h"

namespace pointrast::view {

namespace {

gpu::GraphicsOptions copyOptions(VkFormat format) {
  gpu::GraphicsOptions options;
  options.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  options.colorFormat = format;
  options.depthFormat = VK_FORMAT_UNDEFINED;
  return options;
}

void transition(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to,
                VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                VkAccessFlags2 dstAccess) {
  VkImageMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  barrier.srcStageMask = srcStage;
  barrier.srcAccessMask = srcAccess;
  barrier.dstStageMask = dstStage;
  barrier.dstAccessMask = dstAccess;
  barrier.oldLayout = from;
  barrier.newLayout = to;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image;
  barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dependency.imageMemoryBarrierCount = 1;
  dependency.pImageMemoryBarriers = &barrier;
  gpu::vkCmdPipelineBarrier2(cmd, &dependency);
}

// The renderer's image was written by an earlier submission: its writes must be visible to the fragment
// shader that copies it (a barrier's first scope covers every command submitted before it).
void imageWritesVisible(VkCommandBuffer cmd) {
  VkMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
  barrier.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  barrier.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
  barrier.dstStageMask = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
  barrier.dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT;
  VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dependency.memoryBarrierCount = 1;
  dependency.pMemoryBarriers = &barrier;
  gpu::vkCmdPipelineBarrier2(cmd, &dependency);
}

} // namespace

Presenter::Presenter(gpu::Context& context, gpu::Swapchain& swapchain)
    : context_(context), swapchain_(swapchain),
      copy_(context, "view_present.vert", "view_present.frag", copyOptions(swapchain.format())),
      panel_(context, swapchain.format()), timer_(context, 1) {}

Presenter::Result Presenter::present(const ShownImage& image, const ImDrawData* panel) {
  std::optional<uint32_t> index = swapchain_.acquire();
  if (!index) return {};
  if (panel) panel_.upload(*panel);
  uint32_t width = swapchain_.width(), height = swapchain_.height();
  VkImage target = swapchain_.image(*index);
  context_.submitAndWait(
      [&](VkCommandBuffer cmd) {
        timer_.reset(cmd);
        timer_.begin(cmd, 0);
        imageWritesVisible(cmd);
        // UNDEFINED: the pass overwrites every pixel, the old contents are not needed.
        transition(cmd, target, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                   VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, 0,
                   VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
        VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        color.imageView = swapchain_.view(*index);
        color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        color.loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
        rendering.renderArea = {{0, 0}, {width, height}};
        rendering.layerCount = 1;
        rendering.colorAttachmentCount = 1;
        rendering.pColorAttachments = &color;
        gpu::vkCmdBeginRendering(cmd, &rendering);
        gpu::setViewport(cmd, width, height);
        shared::PresentPush push{image.address, image.width, image.height, width, height};
        copy_.draw(cmd, 3, push);
        if (panel) panel_.record(cmd, *panel, width, height);
        gpu::vkCmdEndRendering(cmd);
        transition(cmd, target, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                   VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_BOTTOM_OF_PIPE_BIT, 0);
        timer_.end(cmd, 0);
      },
      {swapchain_.acquired(), VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, swapchain_.rendered(*index)});
  Result result;
  result.gpuMs = timer_.milliseconds()[0];
  result.presented = swapchain_.present(*index);
  return result;
}

} // namespace pointrast::view
