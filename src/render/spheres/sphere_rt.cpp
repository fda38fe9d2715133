// sphere-rt: the ray-tracing baseline of Gralka et al., "Efficient Sphere Rendering Revisited" (2023), on
// VK_KHR_ray_tracing_pipeline. Before the frames (SphereMethodImpl::build, timed apart from them):
//   1. per part, one AABB per particle in the particles' frame (sphere_rt_aabbs.comp.glsl), then
//      bottom-level structures of that AABB geometry: one per piece of the part, a piece being the whole
//      part unless the build's scratch buffer would exceed the device's largest buffer (64 M spheres need
//      4.51 GiB on an H200, which allows 4 GiB), then the same number of particles per piece, halved until
//      it fits. Parts and pieces are built one after another through one AABB buffer (a part) and one
//      scratch buffer, so that memory stays at one part's worth;
//   2. a top-level structure with one instance per piece (identity transform, custom index = part <<
//      kSphereRtPieceBits | piece).
// A frame: one ray per pixel center (sphere_rt.rgen.glsl); the intersection shader ray-casts the sphere
// with the shared robust intersection and reports the hit at its view depth; the closest hit writes
// sphere-compute's visibility word (depth << 32 | particle index) and sphere-compute's resolve shades it.
#include "render/spheres/sphere_rt.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <map>

#include "base/error.h"
#include "gpu/context.h"
#include "gpu/ray_tracing.h"
#include "gpu/timer.h"
#include "render/spheres/sphere_method.h"
#include "render/spheres/sphere_visibility.h"

namespace pointrast {

void recordSphereAabbs(VkCommandBuffer cmd, const gpu::ComputeProgram& program, uint64_t frame,
                       const ParticlePart& part, uint64_t aabbs) {
  assert(aabbs % 8 == 0 && "AABB data must be 8-byte aligned");
  gpu::Grid grid = gpu::gridFor(part.count, program.groupSize());
  shared::SphereAabbPush push{};
  push.frame = frame;
  push.particles = part.data.address();
  push.aabbs = aabbs;
  push.count = uint32_t(part.count);
  push.groupsX = grid.x;
  program.dispatch(cmd, grid.x, grid.y, push);
}

bool sphereRtSupported(gpu::Context& context, std::string* why) {
  if (!context.features().rayTracing) {
    *why = "the device has no ray tracing pipelines (VK_KHR_ray_tracing_pipeline with "
           "VK_KHR_acceleration_structure)";
    return false;
  }
  return true;
}

namespace {

// One global memory dependency (synchronization2).
void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                   VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess) {
  VkMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
  barrier.srcStageMask = srcStage;
  barrier.srcAccessMask = srcAccess;
  barrier.dstStageMask = dstStage;
  barrier.dstAccessMask = dstAccess;
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.memoryBarrierCount = 1;
  dep.pMemoryBarriers = &barrier;
  gpu::vkCmdPipelineBarrier2(cmd, &dep);
}

constexpr VkPipelineStageFlags2 kBuildStage = VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR;
constexpr VkAccessFlags2 kStructureAccess =
    VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;

struct Programs {
  gpu::RayTracingProgram trace;
  gpu::ComputeProgram aabbs, resolve;
};

class SphereRtMethod : public SphereMethodImpl {
public:
  SphereRtMethod(gpu::Context& context, uint32_t width, uint32_t height)
      : context_(context), width_(width), height_(height), pixels_(uint64_t(width) * height) {
    // vkCmdTraceRaysKHR: width and height within the compute grid's reach, all rays within
    // maxRayDispatchInvocationCount.
    const VkPhysicalDeviceLimits& limits = context.properties().limits;
    uint64_t maxWidth = uint64_t(limits.maxComputeWorkGroupCount[0]) * limits.maxComputeWorkGroupSize[0];
    uint64_t maxHeight = uint64_t(limits.maxComputeWorkGroupCount[1]) * limits.maxComputeWorkGroupSize[1];
    if (width > maxWidth || height > maxHeight ||
        pixels_ > context.rayTracingProperties().maxRayDispatchInvocationCount)
      throw UnsupportedError("sphere-rt cannot trace " + std::to_string(width) + " x " +
                             std::to_string(height) + " rays in one dispatch on '" + context.info().name +
                             "'");
    framebuffer_ = gpu::Buffer(context, pixels_ * 8, gpu::kBufferUsage, gpu::MemoryKind::Device,
                               "sphere-rt visibility buffer");
  }

  void prepare(const SphereSettings& settings, shared::SphereFrame& frame) override {
    frame.framebuffer = framebuffer_.address();
    requestedPieceParticles_ = settings.rtPieceParticles;
  }

  double build(const GpuParticles& particles, SphereTargets& targets) override {
    const VkPhysicalDeviceAccelerationStructurePropertiesKHR& limits =
        context_.accelerationStructureProperties();
    const Programs& p = programs(particleLayoutInfo(particles.layout()).shaderId);
    blas_.clear();
    tlas_ = {};
    // Parts with particles, by their index in the part table.
    std::vector<uint32_t> parts;
    uint64_t maxCount = 1;
    for (uint32_t k = 0; k < particles.parts().size(); ++k)
      if (particles.parts()[k].count > 0) {
        parts.push_back(k);
        maxCount = std::max<uint64_t>(maxCount, particles.parts()[k].count);
      }
    if (particles.parts().size() > (1u << (24 - shared::kSphereRtPieceBits)))
      throw UnsupportedError("sphere-rt: " + std::to_string(particles.parts().size()) +
                             " parts are more than an instance's custom index tells apart");

    // Sizes: one bottom-level structure per piece, built with the same AABB geometry description.
    VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geometry.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
    geometry.geometry.aabbs = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR};
    geometry.geometry.aabbs.stride = kSphereAabbBytes;
    geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR; // no any-hit shader
    VkAccelerationStructureBuildGeometryInfoKHR bottom{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    bottom.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    bottom.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    bottom.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    bottom.geometryCount = 1;
    bottom.pGeometries = &geometry;
    auto sizesFor = [&](uint32_t count) {
      VkAccelerationStructureBuildSizesInfoKHR sizes{
          VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
      gpu::vkGetAccelerationStructureBuildSizesKHR(
          context_.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &bottom, &count, &sizes);
      return sizes;
    };
    // Particles per piece: the whole largest part, or the forced count, halved while the scratch (plus
    // its alignment) or the structure would not fit one buffer.
    const uint64_t bufferLimit = std::min(context_.maxBufferSize(), context_.maxAllocationSize()) -
                                 std::max<uint64_t>(limits.minAccelerationStructureScratchOffsetAlignment, 1);
    uint64_t piece =
        requestedPieceParticles_ > 0 ? std::min<uint64_t>(requestedPieceParticles_, maxCount) : maxCount;
    for (;;) {
      if (piece > limits.maxPrimitiveCount) {
        piece = (piece + 1) / 2;
        continue;
      }
      VkAccelerationStructureBuildSizesInfoKHR sizes = sizesFor(uint32_t(piece));
      if ((sizes.buildScratchSize <= bufferLimit && sizes.accelerationStructureSize <= bufferLimit) ||
          piece == 1)
        break;
      piece = (piece + 1) / 2;
    }
    pieceParticles_ = uint32_t(piece); // for the frames (SphereRtPush)
    if ((maxCount + piece - 1) / piece > (1u << shared::kSphereRtPieceBits))
      throw UnsupportedError("sphere-rt: a part of " + std::to_string(maxCount) +
                             " particles needs more than " +
                             std::to_string(1u << shared::kSphereRtPieceBits) +
                             " bottom-level structures of " + std::to_string(piece) + " on this device");
    struct Piece {
      uint32_t part, index; // the part (in the part table) and the piece's number in it
      uint64_t first;       // its first particle in the part
      uint32_t count;
    };
    std::vector<Piece> pieces;
    uint64_t scratchBytes = 0;
    for (uint32_t k : parts) {
      const uint64_t count = particles.parts()[k].count;
      for (uint64_t first = 0, index = 0; first < count; first += piece, ++index) {
        Piece next{k, uint32_t(index), first, uint32_t(std::min(piece, count - first))};
        VkAccelerationStructureBuildSizesInfoKHR sizes = sizesFor(next.count);
        blas_.emplace_back(
            context_, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize,
            "sphere-rt bottom level, part " + std::to_string(k) + " piece " + std::to_string(index));
        scratchBytes = std::max(scratchBytes, sizes.buildScratchSize);
        pieces.push_back(next);
      }
    }
    if (pieces.size() > limits.maxInstanceCount)
      throw UnsupportedError(
          "sphere-rt: " + std::to_string(pieces.size()) +
          " bottom-level structures are more instances than one top-level structure takes");

    // The instances, written by the host before the submission (which makes them visible to the build).
    uint32_t instanceCount = uint32_t(pieces.size());
    gpu::Buffer instances(context_,
                          std::max<uint64_t>(instanceCount, 1) * sizeof(VkAccelerationStructureInstanceKHR),
                          VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                              VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                          gpu::MemoryKind::Upload, "sphere-rt instances");
    auto* instance = static_cast<VkAccelerationStructureInstanceKHR*>(instances.mapped());
    for (uint32_t i = 0; i < instanceCount; ++i) {
      instance[i] = {};
      instance[i].transform.matrix[0][0] = instance[i].transform.matrix[1][1] =
          instance[i].transform.matrix[2][2] = 1;
      instance[i].instanceCustomIndex = pieces[i].part << shared::kSphereRtPieceBits | pieces[i].index;
      instance[i].mask = 0xFF;
      instance[i].instanceShaderBindingTableRecordOffset = 0;
      instance[i].flags = VK_GEOMETRY_INSTANCE_FORCE_OPAQUE_BIT_KHR;
      instance[i].accelerationStructureReference = blas_[i].address();
    }
    VkAccelerationStructureGeometryKHR instanceGeometry{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    instanceGeometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    instanceGeometry.geometry.instances = {
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR};
    instanceGeometry.geometry.instances.arrayOfPointers = VK_FALSE;
    instanceGeometry.geometry.instances.data.deviceAddress = instances.address(); // 16-byte aligned
    VkAccelerationStructureBuildGeometryInfoKHR top{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    top.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    top.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    top.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    top.geometryCount = 1;
    top.pGeometries = &instanceGeometry;
    VkAccelerationStructureBuildSizesInfoKHR topSizes{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    gpu::vkGetAccelerationStructureBuildSizesKHR(
        context_.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &top, &instanceCount, &topSizes);
    tlas_ = gpu::AccelerationStructure(context_, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR,
                                       topSizes.accelerationStructureSize, "sphere-rt top level");
    scratchBytes = std::max(scratchBytes, topSizes.buildScratchSize);

    // One scratch buffer (aligned to minAccelerationStructureScratchOffsetAlignment) and one AABB buffer,
    // reused by every build in turn.
    gpu::ScratchBuffer scratch(context_, scratchBytes);
    gpu::Buffer aabbs(context_, maxCount * kSphereAabbBytes,
                      VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                          VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                      gpu::MemoryKind::Device, "sphere-rt AABBs");
    gpu::TimestampPool timer(context_, 1);
    context_.submitAndWait([&](VkCommandBuffer cmd) {
      timer.reset(cmd);
      timer.begin(cmd, 0);
      for (size_t i = 0; i < pieces.size(); ++i) {
        const Piece& built = pieces[i];
        if (built.index == 0) {
          // A new part's AABBs; the previous builds have read the old ones (write after read: an execution
          // dependency suffices).
          if (i > 0)
            memoryBarrier(cmd, kBuildStage, VK_ACCESS_2_NONE, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                          VK_ACCESS_2_NONE);
          recordSphereAabbs(cmd, p.aabbs, targets.frameStaging.address(), particles.parts()[built.part],
                            aabbs.address());
        }
        // Build inputs are read as shader reads of the build stage; the scratch, reused, is written and
        // read as acceleration structure memory by the previous build and this one.
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | kBuildStage,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
                      kBuildStage, VK_ACCESS_2_SHADER_READ_BIT | kStructureAccess);
        geometry.geometry.aabbs.data.deviceAddress = aabbs.address() + built.first * kSphereAabbBytes;
        bottom.dstAccelerationStructure = blas_[i].handle();
        bottom.scratchData.deviceAddress = scratch.address();
        VkAccelerationStructureBuildRangeInfoKHR range{built.count, 0, 0, 0};
        const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
        gpu::vkCmdBuildAccelerationStructuresKHR(cmd, 1, &bottom, &ranges);
      }
      // The top level reads the bottom levels and reuses the scratch.
      memoryBarrier(cmd, kBuildStage, VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR, kBuildStage,
                    kStructureAccess);
      top.dstAccelerationStructure = tlas_.handle();
      top.scratchData.deviceAddress = scratch.address();
      VkAccelerationStructureBuildRangeInfoKHR range{instanceCount, 0, 0, 0};
      const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
      gpu::vkCmdBuildAccelerationStructuresKHR(cmd, 1, &top, &ranges);
      // Traversal in later submissions reads the structures (a barrier's scope reaches past its submission).
      memoryBarrier(cmd, kBuildStage, VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
                    VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR,
                    VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
      timer.end(cmd, 0);
    });
    return timer.milliseconds()[0];
  }

  void recordFrame(const SphereDraw& draw, SphereTargets& targets) override {
    VkCommandBuffer cmd = draw.cmd;
    assert(tlas_.handle() && "build() comes before the frames");
    const Programs& p = programs(particleLayoutInfo(draw.particles.layout()).shaderId);
    // Every pixel's word is written by its ray (kEmptyPixel on a miss): no clear.
    shared::SphereRtPush trace{targets.frame.address(), tlas_.address(), pieceParticles_, 0};
    p.trace.traceRays(cmd, width_, height_, trace);
    gpu::fullBarrier(cmd);
    recordSphereResolve(cmd, p.resolve, targets.frame.address(), pixels_);
  }

  void addCounters(SphereStats& stats) override { stats.rtBottomLevels = blas_.size(); }

  std::vector<float> depth() override { return readVisibilityDepth(context_, framebuffer_, pixels_); }
  std::vector<uint32_t> indices() override { return readVisibilityIndices(context_, framebuffer_, pixels_); }

private:
  // Programs per particle layout (specialization constant 0 of every sphere shader).
  const Programs& programs(uint32_t layout) {
    auto found = programs_.find(layout);
    if (found != programs_.end()) return found->second;
    Programs p;
    p.trace = gpu::RayTracingProgram(
        context_, {"sphere_rt.rgen", "sphere_rt.rmiss", "sphere_rt.rint", "sphere_rt.rchit"},
        {{/* LAYOUT= */ 0, layout}});
    p.aabbs = gpu::ComputeProgram(context_, "sphere_rt_aabbs.comp", {{/* LAYOUT= */ 0, layout}});
    p.resolve = gpu::ComputeProgram(context_, "sphere_resolve.comp", {{/* LAYOUT= */ 0, layout}});
    return programs_.emplace(layout, std::move(p)).first->second;
  }

  gpu::Context& context_;
  uint32_t width_, height_;
  uint64_t pixels_;
  gpu::Buffer framebuffer_;
  std::vector<gpu::AccelerationStructure> blas_; // one per piece of a part, in instance order
  gpu::AccelerationStructure tlas_;
  uint32_t requestedPieceParticles_ = 0; // SphereSettings::rtPieceParticles of this frame's settings
  uint32_t pieceParticles_ = 0;          // particles per piece of the structures built (SphereRtPush)
  std::map<uint32_t, Programs> programs_;
};

} // namespace

std::unique_ptr<SphereMethodImpl> createSphereRtMethod(gpu::Context& context, uint32_t width,
                                                       uint32_t height) {
  return std::make_unique<SphereRtMethod>(context, width, height);
}

} // namespace pointrast
