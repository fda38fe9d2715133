#include "gpu/pipeline_parts.h"

#include <algorithm>
#include <string>

#include "base/error.h"

namespace pointrast::gpu {

ShaderModules::~ShaderModules() {
  for (VkShaderModule m : modules_)
    vkDestroyShaderModule(device_, m, nullptr);
}

VkShaderModule ShaderModules::add(std::span<const uint32_t> words) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = words.size_bytes();
  info.pCode = words.data();
  VkShaderModule module = VK_NULL_HANDLE;
  VK_CHECK(vkCreateShaderModule(device_, &info, nullptr, &module));
  modules_.push_back(module);
  return module;
}

VkPipelineLayout createPipelineLayout(VkDevice device, VkShaderStageFlags pushStages,
                                      uint32_t pushConstantSize) {
  VkPushConstantRange range{pushStages, 0, pushConstantSize};
  VkPipelineLayoutCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  info.pushConstantRangeCount = range.size ? 1 : 0;
  info.pPushConstantRanges = &range;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VK_CHECK(vkCreatePipelineLayout(device, &info, nullptr, &layout));
  return layout;
}

void destroyPipeline(VkDevice device, VkPipeline& pipeline, VkPipelineLayout& layout) {
  if (deviceFaulted()) return; // the GPU may still use it: leave it to process exit
  if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
  if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
  pipeline = VK_NULL_HANDLE;
  layout = VK_NULL_HANDLE;
}

void checkSpecDeclared(const std::string& pipeline, std::span<const SpirvReflection> stages,
                       std::span<const SpecConstant> spec) {
  for (const SpecConstant& s : spec)
    if (std::none_of(stages.begin(), stages.end(), [&](const SpirvReflection& r) {
          return std::find(r.specIds.begin(), r.specIds.end(), s.id) != r.specIds.end();
        }))
      throw InternalError("internal error: specialization constant " + std::to_string(s.id) + " given to '" +
                          pipeline + "', whose shaders declare no such constant");
}

uint32_t sharedPushSize(const std::string& pipeline, uint32_t size, uint32_t stageSize) {
  if (stageSize != 0 && size != 0 && stageSize != size)
    throw InternalError("internal error: the stages of '" + pipeline + "' declare push-constant blocks of " +
                        std::to_string(size) + " and " + std::to_string(stageSize) + " bytes");
  return std::max(size, stageSize);
}

Specialization::Specialization(std::span<const SpecConstant> spec) {
  for (const SpecConstant& s : spec) {
    entries_.push_back({s.id, uint32_t(values_.size() * sizeof(uint32_t)), sizeof(uint32_t)});
    values_.push_back(s.value);
  }
  info_ = {uint32_t(entries_.size()), entries_.data(), values_.size() * sizeof(uint32_t), values_.data()};
}

} // namespace pointrast::gpu
