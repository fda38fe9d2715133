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
// Attachments and frame in SphereAttachments (RGBA8 color copied into the shared image at the end of a
// frame, like hw-points; particle index and depth read back for tests only). The timed frame is clear +
// draw + copy.
#include <map>
#include <tuple>

#include "base/error.h"
#include "gpu/context.h"
#include "gpu/graphics.h"
#include "render/spheres/sphere_attachments.h"
#include "render/spheres/sphere_method.h"

namespace pointrast {

namespace {

class SphereHardwareMethod : public SphereMethodImpl {
public:
  SphereHardwareMethod(gpu::Context& context, uint32_t width, uint32_t height, SphereMethod method)
      : context_(context), method_(method), attachments_(context, width, height),
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
    attachments_.begin(cmd, draw.settings.background);
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
    attachments_.end(cmd, targets);
  }

  std::vector<float> depth() override { return attachments_.depth(nearW_); }
  std::vector<uint32_t> indices() override { return attachments_.indices(); }

  void addCounters(SphereStats& stats) override {
    uint32_t counters[4];
    gpu::readBuffer(context_, counters_, 0, counters, sizeof counters);
    stats.clampedSpheres = counters[0];
  }

private:
  // Pipelines per particle layout (specialization constant 0 of every sphere shader), billboard
  // (constant 2 of the vertex stage) and conservative rasterization.
  const gpu::GraphicsProgram& program(uint32_t layout, const SphereSettings& settings) {
    const std::tuple<uint32_t, SphereBillboard, bool> key{layout, settings.billboard, settings.conservative};
    auto found = programs_.find(key);
    if (found != programs_.end()) return found->second;
    gpu::GraphicsOptions options = SphereAttachments::pipelineOptions(layout, settings);
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
  SphereAttachments attachments_;
  gpu::Buffer counters_;
  float nearW_ = 0;
  std::map<std::tuple<uint32_t, SphereBillboard, bool>, gpu::GraphicsProgram> programs_;
};

} // namespace

std::unique_ptr<SphereMethodImpl> createSphereHardwareMethod(gpu::Context& context, uint32_t width,
                                                             uint32_t height, SphereMethod method) {
  return std::make_unique<SphereHardwareMethod>(context, width, height, method);
}

} // namespace pointrast
