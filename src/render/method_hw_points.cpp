// hw-points: the hardware point primitive, the GL_POINTS baseline of the papers (and what Potree,
// CloudCompare and QGIS draw with). A Vulkan point-list pipeline, one vertex per point pulled from the
// part's buffers by gl_VertexIndex, 1-pixel points, the fixed-function depth test on a D32_SFLOAT
// attachment (reverse-Z, see points_hw.vert.glsl), then a copy of the RGBA8 attachment into the shared
// image. It is a plain, fair pipeline: one draw per scene part, no culling or ordering tricks, and the
// timed frame covers clear + draw + copy like the compute methods' clear + raster + resolve.
#include "gpu/context.h"
#include "gpu/graphics.h"
#include "gpu/image.h"
#include "render/method.h"

namespace pointrast {

namespace {

constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM; // byte order r, g, b, a = the image's uint
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
// Reverse-Z: depth = nearW / c.w, so the empty depth is 0 (infinitely far) and nearer means greater.
constexpr float kClearDepth = 0.0f;

class HwPointsMethod : public PointMethod {
public:
  HwPointsMethod(gpu::Context& context, const MethodInfo& method, uint32_t width, uint32_t height)
      : program_(context, method.shader, "points_hw.frag",
                 {VK_PRIMITIVE_TOPOLOGY_POINT_LIST, kColorFormat, kDepthFormat, VK_COMPARE_OP_GREATER}),
        color_(context, width, height, kColorFormat,
               VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "hw-points color"),
        depth_(context, width, height, kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
               "hw-points depth") {}

  void recordFrame(const Frame& frame, Targets& targets) override {
    VkCommandBuffer cmd = frame.cmd;
    // Both attachments are cleared on load, so their old contents are discarded (UNDEFINED). The color
    // image waits for the previous frame's copy out of it, the depth image for the previous depth writes.
    gpu::imageBarrier(cmd, color_,
                      {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE, VK_IMAGE_LAYOUT_UNDEFINED},
                      {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                       VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL});
    constexpr VkPipelineStageFlags2 kDepthStages =
        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
    gpu::imageBarrier(
        cmd, depth_,
        {kDepthStages, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED},
        {kDepthStages,
         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
         VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL});

    uint32_t background = frame.settings.background;
    VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    color.imageView = color_.view();
    color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    color.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    // k / 255 converts back to exactly k in a UNORM attachment (round to nearest).
    for (int c = 0; c < 4; ++c)
      color.clearValue.color.float32[c] = float((background >> (8 * c)) & 0xFFu) / 255.0f;
    VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depth.imageView = depth_.view();
    depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE; // only the color leaves the frame
    depth.clearValue.depthStencil = {kClearDepth, 0};
    VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
    rendering.renderArea = {{0, 0}, {targets.width, targets.height}};
    rendering.layerCount = 1;
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachments = &color;
    rendering.pDepthAttachment = &depth;
    gpu::vkCmdBeginRendering(cmd, &rendering);
    gpu::setViewport(cmd, targets.width, targets.height);
    // One vertex per point: the grid of forEachPart is for compute dispatches and goes unused here.
    forEachPart(frame, targets, 1, shared::RasterPush{}, [&](const shared::RasterPush& push, gpu::Grid) {
      program_.draw(cmd, push.pointCount, push);
    });
    gpu::vkCmdEndRendering(cmd);

    gpu::imageBarrier(
        cmd, color_,
        {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
         VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
        {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL});
    // Tightly packed rows, row 0 at the top: the layout of targets.image.
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {targets.width, targets.height, 1};
    gpu::vkCmdCopyImageToBuffer(cmd, color_.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                targets.image.handle(), 1, &region);
    // As every method ends its frame: the image is complete for whatever reads it next (readback, the
    // next frame's copy).
    gpu::fullBarrier(cmd);
  }

private:
  gpu::GraphicsProgram program_;
  gpu::Image color_;
  gpu::Image depth_;
};

} // namespace

std::unique_ptr<PointMethod> createHwPointsMethod(gpu::Context& context, const MethodInfo& method,
                                                  uint32_t width, uint32_t height) {
  return std::make_unique<HwPointsMethod>(context, method, width, height);
}

} // namespace pointrast
