// sphere-mesh-points and sphere-mesh-tris: the mesh-shader pipelines of Gralka et al., "Efficient Sphere
// Rendering Revisited" (2023), which found mesh shaders the fastest way to draw sphere impostors as
// polygons. A mesh workgroup takes a meshlet of 31 or 15 spheres (--meshlet), one invocation each, and
// emits each visible sphere's impostor (sphere_impostor.inc.glsl, as the vertex pipelines build it) as
// one point or one quad of two triangles; the fragment stage is the shared sphere_impostor.frag.glsl. With
// --task-cull a task shader first culls 128 spheres per workgroup and launches mesh workgroups only for
// the survivors. Attachments and frame as in sphere_hardware.cpp (SphereAttachments).
#include "render/spheres/sphere_mesh.h"

#include <algorithm>
#include <cassert>
#include <map>
#include <tuple>

#include "base/error.h"
#include "gpu/context.h"
#include "gpu/graphics.h"
#include "render/spheres/sphere_attachments.h"

namespace pointrast {

std::vector<MeshDraw> planMeshDraws(uint64_t count, uint32_t spheresPerGroup, uint32_t maxTotal,
                                    uint32_t maxX, uint32_t maxY) {
  assert(spheresPerGroup > 0 && maxTotal > 0 && maxX > 0 && maxY > 0);
  uint64_t groups = (count + spheresPerGroup - 1) / spheresPerGroup;
  // Shaders compute the sphere index (firstGroup + y * groupsX + x) * spheresPerGroup + lane in 32 bits.
  assert((groups + 1) * spheresPerGroup <= (uint64_t(1) << 32));
  std::vector<MeshDraw> draws;
  uint64_t x = std::min<uint64_t>({groups, maxX, maxTotal});
  if (x == 0) return draws;
  uint64_t rows = std::min<uint64_t>(maxY, maxTotal / x); // >= 1: x <= maxTotal
  uint64_t first = 0;
  while (groups - first >= x) {
    uint64_t r = std::min(rows, (groups - first) / x);
    draws.push_back({uint32_t(first), uint32_t(x), uint32_t(r)});
    first += x * r;
  }
  if (first < groups) draws.push_back({uint32_t(first), uint32_t(groups - first), 1});
  return draws;
}

namespace {

uint64_t roundUp(uint64_t value, uint32_t granularity) {
  granularity = std::max(granularity, 1u);
  return (value + granularity - 1) / granularity * granularity;
}

bool atLeast(uint32_t limit, uint64_t needed, const char* name, std::string* why) {
  if (limit >= needed) return true;
  if (why)
    *why =
        std::string(name) + " is " + std::to_string(limit) + ", the pipeline needs " + std::to_string(needed);
  return false;
}

} // namespace

bool meshletFits(const VkPhysicalDeviceMeshShaderPropertiesEXT& limits, uint32_t meshlet, bool points,
                 bool task, std::string* why) {
  uint32_t vertices = meshOutputVertices(meshlet, points), primitives = meshOutputPrimitives(meshlet, points);
  uint32_t components = kMeshVertexComponents + (points ? 1 : 0);
  // Output memory as VK_EXT_mesh_shader counts it: vertices and primitives rounded up to the device's
  // granularities, 4 bytes per component, and the primitive's indices (1 per point, 3 per triangle).
  uint64_t outputBytes = roundUp(vertices, limits.meshOutputPerVertexGranularity) * components * 4 +
                         roundUp(primitives, limits.meshOutputPerPrimitiveGranularity) * (points ? 1 : 3) * 4;
  if (!atLeast(limits.maxMeshWorkGroupInvocations, meshlet, "maxMeshWorkGroupInvocations", why) ||
      !atLeast(limits.maxMeshWorkGroupSize[0], meshlet, "maxMeshWorkGroupSize[0]", why) ||
      !atLeast(limits.maxMeshOutputVertices, vertices, "maxMeshOutputVertices", why) ||
      !atLeast(limits.maxMeshOutputPrimitives, primitives, "maxMeshOutputPrimitives", why) ||
      !atLeast(limits.maxMeshOutputComponents, components, "maxMeshOutputComponents", why) ||
      !atLeast(limits.maxMeshOutputMemorySize, outputBytes, "maxMeshOutputMemorySize", why) ||
      !atLeast(limits.maxMeshSharedMemorySize, kMeshSharedBytes, "maxMeshSharedMemorySize", why) ||
      !atLeast(limits.maxMeshWorkGroupTotalCount, 1, "maxMeshWorkGroupTotalCount", why) ||
      !atLeast(limits.maxMeshWorkGroupCount[0], 1, "maxMeshWorkGroupCount[0]", why) ||
      !atLeast(limits.maxMeshWorkGroupCount[1], 1, "maxMeshWorkGroupCount[1]", why))
    return false;
  if (!task) return true;
  // The task shader launches at most ceil(128 / meshlet) mesh workgroups along x.
  uint32_t launched = (shared::kSphereTaskSpheres + meshlet - 1) / meshlet;
  return atLeast(limits.maxTaskWorkGroupInvocations, shared::kSphereTaskGroupSize,
                 "maxTaskWorkGroupInvocations", why) &&
         atLeast(limits.maxTaskWorkGroupSize[0], shared::kSphereTaskGroupSize, "maxTaskWorkGroupSize[0]",
                 why) &&
         atLeast(limits.maxTaskPayloadSize, kMeshPayloadBytes, "maxTaskPayloadSize", why) &&
         atLeast(limits.maxTaskSharedMemorySize, kTaskSharedBytes, "maxTaskSharedMemorySize", why) &&
         atLeast(limits.maxTaskPayloadAndSharedMemorySize, kMeshPayloadBytes + kTaskSharedBytes,
                 "maxTaskPayloadAndSharedMemorySize", why) &&
         atLeast(limits.maxMeshPayloadAndSharedMemorySize, kMeshPayloadBytes + kMeshSharedBytes,
                 "maxMeshPayloadAndSharedMemorySize", why) &&
         atLeast(limits.maxMeshPayloadAndOutputMemorySize, kMeshPayloadBytes + outputBytes,
                 "maxMeshPayloadAndOutputMemorySize", why) &&
         atLeast(limits.maxMeshWorkGroupCount[0], launched, "maxMeshWorkGroupCount[0]", why) &&
         atLeast(limits.maxTaskWorkGroupTotalCount, 1, "maxTaskWorkGroupTotalCount", why) &&
         atLeast(limits.maxTaskWorkGroupCount[0], 1, "maxTaskWorkGroupCount[0]", why) &&
         atLeast(limits.maxTaskWorkGroupCount[1], 1, "maxTaskWorkGroupCount[1]", why);
}

std::string meshShaderName(uint32_t meshlet, bool points, bool task) {
  return std::string("sphere_mesh_") + (points ? "points" : "tris") + std::to_string(meshlet) +
         (task ? "_task" : "") + ".mesh";
}

bool sphereMeshSupported(gpu::Context& context, bool points, std::string* why) {
  const gpu::DeviceFeatures& f = context.features();
  if (!f.meshShader) {
    *why = "the device has no mesh shaders (VK_EXT_mesh_shader)";
    return false;
  }
  if (points && (!f.largePoints || context.properties().limits.pointSizeRange[1] <= 1.0f)) {
    *why = "the device draws no points larger than one pixel (largePoints)";
    return false;
  }
  // Both meshlet sizes: the larger needs more of every limit.
  std::string limit;
  if (meshletFits(context.meshShaderProperties(), shared::kSphereMeshletLarge, points, false, &limit))
    return true;
  *why = "its mesh-shader limits are too small for meshlets of " +
         std::to_string(shared::kSphereMeshletLarge) + " spheres: " + limit;
  return false;
}

namespace {

class SphereMeshMethod : public SphereMethodImpl {
public:
  SphereMeshMethod(gpu::Context& context, uint32_t width, uint32_t height, SphereMethod method)
      : context_(context), method_(method), points_(method == SphereMethod::MeshPoints),
        attachments_(context, width, height),
        counters_(context, 16, gpu::kBufferUsage, gpu::MemoryKind::Device, "sphere frame counters") {}

  void prepare(const SphereSettings& settings, shared::SphereFrame& frame) override {
    std::string why;
    if (settings.taskCull && !context_.features().taskShader)
      why = "the device has no task shaders (taskShader)";
    else
      meshletFits(context_.meshShaderProperties(), settings.meshlet, points_, settings.taskCull, &why);
    if (!why.empty())
      throw UnsupportedError(std::string(sphereMethodName(method_)) + " with meshlets of " +
                             std::to_string(settings.meshlet) + " spheres" +
                             (settings.taskCull ? " and task-shader culling" : "") +
                             " is not available on '" + context_.info().name + "': " + why);
    frame.counters = counters_.address();
    frame.maxPointSize = context_.properties().limits.pointSizeRange[1];
    nearW_ = frame.nearW;
  }

  void recordFrame(const SphereDraw& draw, SphereTargets& targets) override {
    VkCommandBuffer cmd = draw.cmd;
    const SphereSettings& settings = draw.settings;
    const gpu::GraphicsProgram& program =
        this->program(particleLayoutInfo(draw.particles.layout()).shaderId, settings);
    gpu::vkCmdFillBuffer(cmd, counters_.handle(), 0, 16, 0);
    gpu::fullBarrier(cmd);
    attachments_.begin(cmd, settings.background);
    // Without task shader: one mesh workgroup per meshlet. With: one task workgroup per 128 spheres, each
    // launching its own mesh workgroups.
    const VkPhysicalDeviceMeshShaderPropertiesEXT& limits = context_.meshShaderProperties();
    uint32_t perGroup = settings.taskCull ? shared::kSphereTaskSpheres : settings.meshlet;
    uint32_t maxTotal =
        settings.taskCull ? limits.maxTaskWorkGroupTotalCount : limits.maxMeshWorkGroupTotalCount;
    const uint32_t* maxCount =
        settings.taskCull ? limits.maxTaskWorkGroupCount : limits.maxMeshWorkGroupCount;
    shared::SpherePush push{};
    push.frame = targets.frame.address();
    for (const ParticlePart& part : draw.particles.parts()) {
      push.particles = part.data.address();
      push.first = uint32_t(part.first);
      push.count = uint32_t(part.count);
      for (const MeshDraw& d : planMeshDraws(part.count, perGroup, maxTotal, maxCount[0], maxCount[1])) {
        push.groupsX = d.groupsX;
        push.firstGroup = d.firstGroup;
        program.drawMeshTasks(cmd, d.groupsX, d.groupsY, push);
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
  // Pipelines per particle layout (specialization constant 0 of every sphere shader), billboard (2),
  // conservative rasterization, meshlet and task culling (the meshlet is constant 1 of the task shader).
  const gpu::GraphicsProgram& program(uint32_t layout, const SphereSettings& settings) {
    auto key = std::make_tuple(layout, settings.billboard, settings.conservative, settings.meshlet,
                               settings.taskCull);
    auto found = programs_.find(key);
    if (found != programs_.end()) return found->second;
    gpu::GraphicsOptions options = SphereAttachments::pipelineOptions(layout, settings);
    options.meshShader = true;
    options.topology = points_ ? VK_PRIMITIVE_TOPOLOGY_POINT_LIST : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    if (settings.taskCull) {
      options.taskShader = "sphere_mesh.task";
      options.spec.push_back({/* MESHLET= */ 1, settings.meshlet});
    }
    std::string mesh = meshShaderName(settings.meshlet, points_, settings.taskCull);
    return programs_.emplace(key, gpu::GraphicsProgram(context_, mesh, "sphere_impostor.frag", options))
        .first->second;
  }

  gpu::Context& context_;
  SphereMethod method_;
  bool points_;
  SphereAttachments attachments_;
  gpu::Buffer counters_;
  float nearW_ = 0;
  std::map<std::tuple<uint32_t, SphereBillboard, bool, uint32_t, bool>, gpu::GraphicsProgram> programs_;
};

} // namespace

std::unique_ptr<SphereMethodImpl> createSphereMeshMethod(gpu::Context& context, uint32_t width,
                                                         uint32_t height, SphereMethod method) {
  return std::make_unique<SphereMeshMethod>(context, width, height, method);
}

} // namespace pointrast
