// The rasterization sphere pipelines of Gralka et al., "Efficient Sphere Rendering Revisited" (2023): each
// sphere becomes an impostor over the exact bounds of its projection, and the fragment shader ray-casts
// it (shaders/sphere_impostor.frag.glsl, with the shading every sphere method shares), writing color,
// particle index and the hit's depth (reverse-Z, conservative depth_less). They differ in how the
// impostor reaches the rasterizer:
//   sphere-points     one point per sphere, gl_PointSize from the bounds (clamped to the device's largest)
//   sphere-triangles  a triangle list, 6 vertices per sphere
//   sphere-strip      one instance per sphere of a 4-vertex triangle strip
//   sphere-geom       one point per sphere, expanded into a strip by a geometry shader
// Every pipeline takes both billboards of the study (SphereSettings::billboard: the tight screen-space box
// of the projection, or the camera-aligned square of sphere_impostor.inc.glsl) and optionally overestimating
// conservative rasterization; the images are the same, only the fragments spent on them differ.
// Attachments: RGBA8 color (copied into the shared image at the end of a frame, like hw-points), R32_UINT
// particle index and D32 depth (read back for tests only). The timed frame is clear + draw + copy.
#include <algorithm>
#include <cstring>
#include <limits>
#include <map>
#include <tuple>

#include "base/error.h"
#include "gpu/context.h"
#include "gpu/graphics.h"
#include "gpu/image.h"
#include "render/spheres/sphere_method.h"

namespace pointrast {

namespace {

constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM; // byte order r, g, b, a = the image's uint
constexpr VkFormat kIndexFormat = VK_FORMAT_R32_UINT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
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

class SphereHardwareMethod : public SphereMethodImpl {
public:
  SphereHardwareMethod(gpu::Context& context, uint32_t width, uint32_t height, SphereMethod method)
      : context_(context), method_(method),
        color_(context, width, height, kColorFormat,
               VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "sphere color"),
        index_(context, width, height, kIndexFormat,
               VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
               "sphere particle index"),
        depth_(context, width, height, kDepthFormat,
               VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "sphere depth"),
        counters_(context, 16, gpu::kBufferUsage, gpu::MemoryKind::Device, "sphere frame counters") {}

  void prepare(const SphereSettings&, shared::SphereFrame& frame) override {
    frame.counters = counters_.address();
    frame.maxPointSize = context_.properties().limits.pointSizeRange[1];
    nearW_ = frame.nearW;
  }

  void recordFrame(const SphereDraw& draw, SphereTargets& targets) override {
    VkCommandBuffer cmd = draw.cmd;
    const gpu::GraphicsProgram& program =
        this->program(particleLayoutInfo(draw.particles.layout()).shaderId, draw.settings);
    gpu::vkCmdFillBuffer(cmd, counters_.handle(), 0, 16, 0);
    gpu::fullBarrier(cmd);
    // Every attachment is cleared on load: old contents are discarded (UNDEFINED). The color image waits
    // for the previous frame's copy out of it.
    gpu::imageBarrier(cmd, color_,
                      {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE, VK_IMAGE_LAYOUT_UNDEFINED},
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
      colors[0].clearValue.color.float32[c] = float((draw.settings.background >> (8 * c)) & 0xFFu) / 255.0f;
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
    rendering.renderArea = {{0, 0}, {targets.width, targets.height}};
    rendering.layerCount = 1;
    rendering.colorAttachmentCount = 2;
    rendering.pColorAttachments = colors;
    rendering.pDepthAttachment = &depth;
    gpu::vkCmdBeginRendering(cmd, &rendering);
    gpu::setViewport(cmd, targets.width, targets.height);
    shared::SpherePush push{};
    push.frame = targets.frame.address();
    for (const ParticlePart& part : draw.particles.parts()) {
      push.particles = part.data.address();
      push.first = uint32_t(part.first);
      push.count = uint32_t(part.count);
      switch (method_) {
      case SphereMethod::Triangles:
        program.draw(cmd, push.count * 6, push); // parts hold at most 64 M particles: no overflow
        break;
      case SphereMethod::Strip:
        program.draw(cmd, 4, push, push.count);
        break;
      default: // points, geometry: one vertex per sphere
        program.draw(cmd, push.count, push);
        break;
      }
    }
    gpu::vkCmdEndRendering(cmd);

    gpu::imageBarrier(cmd, color_, kColorAttachment, kCopySource);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {targets.width, targets.height, 1};
    gpu::vkCmdCopyImageToBuffer(cmd, color_.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                targets.image.handle(), 1, &region);
    gpu::fullBarrier(cmd);
  }

  std::vector<float> depth() override {
    std::vector<float> z = readImage<float>(depth_, kDepthAttachment, VK_IMAGE_ASPECT_DEPTH_BIT);
    for (float& d : z)
      d = d > 0 ? nearW_ / d : std::numeric_limits<float>::infinity();
    return z;
  }

  std::vector<uint32_t> indices() override {
    return readImage<uint32_t>(index_, kColorAttachment, VK_IMAGE_ASPECT_COLOR_BIT);
  }

  void addCounters(SphereStats& stats) override {
    uint32_t counters[4];
    gpu::readBuffer(context_, counters_, 0, counters, sizeof counters);
    stats.clampedSpheres = counters[0];
  }

private:
  // Copies an attachment of the last frame into host memory and leaves it in its attachment layout.
  template <class T>
  std::vector<T> readImage(const gpu::Image& image, gpu::ImageUse use, VkImageAspectFlags aspect) {
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

  // Pipelines per particle layout (specialization constant 0 of every sphere shader), billboard
  // (constant 2 of the vertex stage) and conservative rasterization.
  const gpu::GraphicsProgram& program(uint32_t layout, const SphereSettings& settings) {
    const uint32_t billboard = settings.billboard == SphereBillboard::Camera ? shared::kSphereBillboardCamera
                                                                             : shared::kSphereBillboardScreen;
    const std::tuple<uint32_t, uint32_t, bool> key{layout, billboard, settings.conservative};
    auto found = programs_.find(key);
    if (found != programs_.end()) return found->second;
    gpu::GraphicsOptions options;
    options.colorFormat = kColorFormat;
    options.depthFormat = kDepthFormat;
    options.depthCompare = VK_COMPARE_OP_GREATER;
    options.secondColorFormat = kIndexFormat;
    options.conservative = settings.conservative;
    options.spec = {{/* LAYOUT= */ 0, layout}, {/* BILLBOARD= */ 2, billboard}};
    std::string vertex;
    switch (method_) {
    case SphereMethod::Points:
      options.topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
      vertex = "sphere_points.vert";
      break;
    case SphereMethod::Triangles:
    case SphereMethod::Strip:
      options.topology = method_ == SphereMethod::Strip ? VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP
                                                        : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
      vertex = "sphere_quads.vert";
      options.spec.push_back({/* QUAD= */ 1, method_ == SphereMethod::Strip ? shared::kSphereQuadStrip
                                                                            : shared::kSphereQuadTriangles});
      break;
    default:
      options.topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
      vertex = "sphere_geom.vert";
      options.geometryShader = "sphere_geom.geom";
      break;
    }
    return programs_.emplace(key, gpu::GraphicsProgram(context_, vertex, "sphere_impostor.frag", options))
        .first->second;
  }

  gpu::Context& context_;
  SphereMethod method_;
  gpu::Image color_, index_, depth_;
  gpu::Buffer counters_;
  float nearW_ = 0;
  std::map<std::tuple<uint32_t, uint32_t, bool>, gpu::GraphicsProgram> programs_;
};

} // namespace

std::unique_ptr<SphereMethodImpl> createSphereHardwareMethod(gpu::Context& context, uint32_t width,
                                                             uint32_t height, SphereMethod method) {
  return std::make_unique<SphereHardwareMethod>(context, width, height, method);
}

} // namespace pointrast
