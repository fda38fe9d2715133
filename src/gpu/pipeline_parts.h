// The parts every pipeline kind (compute, graphics, ray tracing) builds the same way: shader modules of
// embedded SPIR-V, the specialization constants named at the call site, and the pipeline layout (one
// push-constant range of the reflected size, no descriptor sets: buffers are passed by device address).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "gpu/program.h"
#include "gpu/spirv_reflect.h"
#include "gpu/vulkan_api.h"

namespace pointrast::gpu {

// The shader modules of one pipeline being made, destroyed with this object: once the pipeline exists (or
// failed), nothing needs them.
class ShaderModules {
public:
  explicit ShaderModules(VkDevice device) : device_(device) {}
  ~ShaderModules();
  ShaderModules(const ShaderModules&) = delete;
  ShaderModules& operator=(const ShaderModules&) = delete;

  // A module of the words, appended.
  VkShaderModule add(std::span<const uint32_t> words);
  VkShaderModule operator[](size_t i) const { return modules_[i]; }

private:
  VkDevice device_;
  std::vector<VkShaderModule> modules_;
};

// A layout of one push-constant range [0, pushConstantSize) seen by `pushStages`, or of none when the
// size is 0.
VkPipelineLayout createPipelineLayout(VkDevice device, VkShaderStageFlags pushStages,
                                      uint32_t pushConstantSize);

// Destroys a pipeline and its layout (either may be null) and nulls both; not after a device fault, when
// the GPU may still use them: they are left to process exit.
void destroyPipeline(VkDevice device, VkPipeline& pipeline, VkPipelineLayout& layout);

// Throws InternalError naming `pipeline` unless some stage declares every constant of `spec` (a misspelt
// id in a method table row would otherwise be ignored). Checked in every build: benchmarks run Release.
void checkSpecDeclared(const std::string& pipeline, std::span<const SpirvReflection> stages,
                       std::span<const SpecConstant> spec);

// The push-constant size of a pipeline whose stages so far declare `size` bytes, after one more stage that
// declares `stageSize`: every stage sees the same block from offset 0 (one struct from shared.h), or none.
// Throws InternalError naming `pipeline` when two stages declare different blocks.
uint32_t sharedPushSize(const std::string& pipeline, uint32_t size, uint32_t stageSize);

// The specialization of every stage of a pipeline: 4-byte values in the order of `spec`. Not copyable:
// info() points into it.
class Specialization {
public:
  explicit Specialization(std::span<const SpecConstant> spec);
  Specialization(const Specialization&) = delete;
  Specialization& operator=(const Specialization&) = delete;

  // The stages' pSpecializationInfo: null without constants.
  const VkSpecializationInfo* info() const { return entries_.empty() ? nullptr : &info_; }

private:
  std::vector<VkSpecializationMapEntry> entries_;
  std::vector<uint32_t> values_;
  VkSpecializationInfo info_{};
};

} // namespace pointrast::gpu
