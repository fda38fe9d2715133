// Compute programs built from embedded SPIR-V. The pipeline layout is derived from the module (one
// push-constant range of the reflected size, no descriptor sets: buffers are passed by device address),
// and variants are specialization constants named at the call site:
//
//   ComputeProgram earlyZ(ctx, "raster_closest.comp", {{/* EARLY_Z= */ 0, 1}});
//   earlyZ.dispatch(cmd, groups, push);  // checks sizeof(push) == the shader's push-constant block
#pragma once

#include <cassert>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "gpu/spirv_reflect.h"
#include "gpu/vulkan_api.h"

namespace pointrast::gpu {

class Context;

struct SpecConstant {
  uint32_t id;
  uint32_t value;
};

// What every pipeline kind (compute, graphics, ray tracing) owns and how it ends: the pipeline and its
// layout, destroyed with the object (but not after a device fault, when the GPU may still use them), the
// push-constant block its shaders declare, and a name for messages. Move-only.
class Pipeline {
public:
  uint32_t pushConstantSize() const { return pushConstantSize_; }
  const std::string& name() const { return name_; }

protected:
  Pipeline() = default;
  Pipeline(VkDevice device, std::string name) : device_(device), name_(std::move(name)) {}
  ~Pipeline();
  Pipeline(Pipeline&& other) noexcept { *this = std::move(other); }
  Pipeline& operator=(Pipeline&& other) noexcept;
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Binds the pipeline and pushes `size` bytes of constants, after checking that size against the block
  // the shaders declare (checkPushSize).
  void bind(VkCommandBuffer cmd, VkPipelineBindPoint point, const void* push, uint32_t size) const;

  VkDevice device_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  uint32_t pushConstantSize_ = 0;
  VkShaderStageFlags pushStages_ = 0;
  std::string name_;
};

class ComputeProgram : public Pipeline {
public:
  ComputeProgram() = default;
  ComputeProgram(Context& context, const std::string& shaderName,
                 std::initializer_list<SpecConstant> spec = {})
      : ComputeProgram(context, shaderName, std::span<const SpecConstant>(spec.begin(), spec.size())) {}
  ComputeProgram(Context& context, const std::string& shaderName, std::span<const SpecConstant> spec);

  uint32_t groupSize() const {
    return reflection_.localSize[0] * reflection_.localSize[1] * reflection_.localSize[2];
  }

  template <class Push>
  void dispatch(VkCommandBuffer cmd, uint32_t groupsX, uint32_t groupsY, const Push& push) const {
    dispatchRaw(cmd, groupsX, groupsY, &push, sizeof(Push));
  }

private:
  void dispatchRaw(VkCommandBuffer cmd, uint32_t groupsX, uint32_t groupsY, const void* push,
                   uint32_t size) const;
  SpirvReflection reflection_;
};

// Throws std::logic_error unless `given` bytes of push constants match the `declared` block of `program`'s
// shaders: a struct out of step with its shader is a build mistake, caught in every build (benchmarks run
// Release builds) before it reaches the device.
void checkPushSize(const std::string& program, uint32_t given, uint32_t declared);

// Workgroup grid for `items` work items in groups of groupSize: a 2D grid when one row would exceed the
// 65535 groups every device must support. Shaders recover the linear index with groupsX.
struct Grid {
  uint32_t x = 0, y = 0;
};
Grid gridFor(uint64_t items, uint32_t groupSize);

} // namespace pointrast::gpu
