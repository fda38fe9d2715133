// Ray tracing (VK_KHR_ray_tracing_pipeline + VK_KHR_acceleration_structure, DeviceFeatures::rayTracing):
// acceleration structures in their own buffers, and a ray tracing program built from embedded SPIR-V like
// ComputeProgram and GraphicsProgram: the layout comes from the modules (one push-constant range of the
// reflected size, no descriptor sets: the top-level structure is passed by device address and shaders
// use accelerationStructureEXT(address)), variants are specialization constants, and the shader binding
// table is laid out and filled at construction.
//
//   RayTracingProgram rt(ctx, {"x.rgen", "x.rmiss", "x.rint", "x.rchit"}, {{/* LAYOUT= */ 0, layout}});
//   rt.traceRays(cmd, width, height, push); // checks sizeof(push) == the shaders' push-constant block
#pragma once

#include <cassert>
#include <cstdint>
#include <string>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/program.h"
#include "gpu/vulkan_api.h"

namespace pointrast::gpu {

class Context;

constexpr uint64_t alignUp(uint64_t value, uint64_t alignment) {
  return alignment <= 1 ? value : (value + alignment - 1) / alignment * alignment;
}

// Where the records of the shader groups lie in a shader binding table: ray generation, then the miss
// records, then the hit-group records, each region starting at a multiple of shaderGroupBaseAlignment,
// records `stride` apart (the handle size rounded up to shaderGroupHandleAlignment). The ray generation
// region's size equals its stride, as vkCmdTraceRaysKHR requires. Offsets are from the table's start,
// which itself must lie at a multiple of baseAlignment.
struct ShaderBindingTableLayout {
  uint64_t stride = 0;
  uint64_t rayGenOffset = 0, missOffset = 0, hitOffset = 0;
  uint64_t rayGenSize = 0, missSize = 0, hitSize = 0;
  uint64_t size = 0; // bytes of the whole table
};
// Preconditions: handleSize > 0; the alignments are powers of two (Vulkan guarantees both).
ShaderBindingTableLayout shaderBindingTableLayout(uint32_t handleSize, uint32_t handleAlignment,
                                                  uint32_t baseAlignment, uint32_t missGroups,
                                                  uint32_t hitGroups);

// An acceleration structure with its own device-local buffer. Build it with
// vkCmdBuildAccelerationStructuresKHR.
class AccelerationStructure {
public:
  AccelerationStructure() = default;
  AccelerationStructure(Context& context, VkAccelerationStructureTypeKHR type, uint64_t size,
                        const std::string& name);
  ~AccelerationStructure();
  AccelerationStructure(AccelerationStructure&& other) noexcept;
  AccelerationStructure& operator=(AccelerationStructure&& other) noexcept;
  AccelerationStructure(const AccelerationStructure&) = delete;
  AccelerationStructure& operator=(const AccelerationStructure&) = delete;

  VkAccelerationStructureKHR handle() const { return handle_; }
  uint64_t address() const { return address_; } // for instances, and accelerationStructureEXT(address)
  uint64_t bytes() const { return storage_.size(); }

private:
  void release();
  VkDevice device_ = VK_NULL_HANDLE;
  Buffer storage_;
  VkAccelerationStructureKHR handle_ = VK_NULL_HANDLE;
  uint64_t address_ = 0;
};

// A buffer for the scratch memory of acceleration structure builds, whose address() is a multiple of
// minAccelerationStructureScratchOffsetAlignment (the buffer is that much larger than `size`).
class ScratchBuffer {
public:
  ScratchBuffer() = default;
  ScratchBuffer(Context& context, uint64_t size);
  uint64_t address() const { return alignedAddress_; }
  uint64_t size() const { return size_; }

private:
  Buffer buffer_;
  uint64_t alignedAddress_ = 0;
  uint64_t size_ = 0;
};

struct RayTracingShaders {
  std::string rayGen;       // e.g. "sphere_rt.rgen"
  std::string miss;         // miss index 0
  std::string intersection; // hit group 0: a procedural (AABB) hit group of intersection + closest hit
  std::string closestHit;
};

class RayTracingProgram : public Pipeline {
public:
  RayTracingProgram() = default;
  RayTracingProgram(Context& context, const RayTracingShaders& shaders, std::vector<SpecConstant> spec = {});

  // Binds the pipeline, pushes the constants and traces width x height rays (one per launch id).
  template <class Push>
  void traceRays(VkCommandBuffer cmd, uint32_t width, uint32_t height, const Push& push) const {
    traceRaysRaw(cmd, width, height, &push, sizeof(Push));
  }

private:
  void traceRaysRaw(VkCommandBuffer cmd, uint32_t width, uint32_t height, const void* push,
                    uint32_t size) const;
  Buffer table_; // the shader binding table, device-local
  VkStridedDeviceAddressRegionKHR rayGen_{}, miss_{}, hit_{}, callable_{};
};

} // namespace pointrast::gpu
