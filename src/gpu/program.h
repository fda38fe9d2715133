// Compute programs built from embedded SPIR-V. The pipeline layout is derived from the module (one
// push-constant range of the reflected size, no descriptor sets: buffers are passed by device address),
// and variants are specialization constants named at the call site:
//
//   ComputeProgram earlyZ(ctx, "raster_earlyz.comp", {{/* EARLY_Z= */ 0, 1}});
//   earlyZ.dispatch(cmd, groups, push);  // asserts sizeof(push) == the shader's push-constant block
#pragma once

#include <cassert>
#include <cstdint>
#include <initializer_list>
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

class ComputeProgram {
public:
  ComputeProgram() = default;
  ComputeProgram(Context& context, const std::string& shaderName,
                 std::initializer_list<SpecConstant> spec = {});
  ~ComputeProgram();
  ComputeProgram(ComputeProgram&& other) noexcept;
  ComputeProgram& operator=(ComputeProgram&& other) noexcept;
  ComputeProgram(const ComputeProgram&) = delete;
  ComputeProgram& operator=(const ComputeProgram&) = delete;

  uint32_t groupSize() const {
    return reflection_.localSize[0] * reflection_.localSize[1] * reflection_.localSize[2];
  }
  uint32_t pushConstantSize() const { return reflection_.pushConstantSize; }
  const std::string& name() const { return name_; }

  template <class Push>
  void dispatch(VkCommandBuffer cmd, uint32_t groupsX, uint32_t groupsY, const Push& push) const {
    assert(sizeof(Push) == reflection_.pushConstantSize && "push-constant struct does not match the shader");
    dispatchRaw(cmd, groupsX, groupsY, &push, sizeof(Push));
  }

private:
  void dispatchRaw(VkCommandBuffer cmd, uint32_t groupsX, uint32_t groupsY, const void* push,
                   uint32_t size) const;
  void release();
  VkDevice device_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  SpirvReflection reflection_;
  std::string name_;
};

// Workgroup grid for `items` work items in groups of groupSize: a 2D grid when one row would exceed the
// 65535 groups every device must support. Shaders recover the linear index with groupsX.
struct Grid {
  uint32_t x = 0, y = 0;
};
Grid gridFor(uint64_t items, uint32_t groupSize);

} // namespace pointrast::gpu
