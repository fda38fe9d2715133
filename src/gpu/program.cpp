#include "gpu/program.h"

#include <algorithm>
#include <stdexcept>

#include "gpu/context.h"
#include "gpu/pipeline_parts.h"
#include "gpu/shader_registry.h"

namespace pointrast::gpu {

Pipeline::~Pipeline() {
  destroyPipeline(device_, pipeline_, layout_);
}

Pipeline& Pipeline::operator=(Pipeline&& other) noexcept {
  if (this != &other) {
    destroyPipeline(device_, pipeline_, layout_);
    device_ = other.device_;
    layout_ = std::exchange(other.layout_, VK_NULL_HANDLE);
    pipeline_ = std::exchange(other.pipeline_, VK_NULL_HANDLE);
    pushConstantSize_ = other.pushConstantSize_;
    pushStages_ = other.pushStages_;
    name_ = std::move(other.name_);
  }
  return *this;
}

void Pipeline::bind(VkCommandBuffer cmd, VkPipelineBindPoint point, const void* push, uint32_t size) const {
  checkPushSize(name_, size, pushConstantSize_);
  vkCmdBindPipeline(cmd, point, pipeline_);
  if (size) vkCmdPushConstants(cmd, layout_, pushStages_, 0, size, push);
}

// The pipeline and layout belong to Pipeline from the moment they exist: a throw below destroys them.
ComputeProgram::ComputeProgram(Context& context, const std::string& shaderName,
                               std::span<const SpecConstant> spec)
    : Pipeline(context.device(), shaderName) {
  std::span<const uint32_t> words = findShader(shaderName);
  reflection_ = reflectSpirv(words);
  pushConstantSize_ = reflection_.pushConstantSize;
  pushStages_ = VK_SHADER_STAGE_COMPUTE_BIT;
  assertSpecDeclared({&reflection_, 1}, spec);
  ShaderModules modules(device_);
  VkShaderModule module = modules.add(words);
  layout_ = createPipelineLayout(device_, pushStages_, pushConstantSize_);
  Specialization specialization(spec);
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = specialization.info();
  info.layout = layout_;
  VK_CHECK(vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_));
  context.setName(VK_OBJECT_TYPE_PIPELINE, uint64_t(pipeline_), shaderName);
}

void ComputeProgram::dispatchRaw(VkCommandBuffer cmd, uint32_t groupsX, uint32_t groupsY, const void* push,
                                 uint32_t size) const {
  if (groupsX == 0 || groupsY == 0) {
    checkPushSize(name_, size, pushConstantSize_);
    return;
  }
  bind(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, push, size);
  vkCmdDispatch(cmd, groupsX, groupsY, 1);
}

void checkPushSize(const std::string& program, uint32_t given, uint32_t declared) {
  if (given != declared)
    throw std::logic_error("internal error: " + std::to_string(given) + " bytes of push constants for '" +
                           program + "', whose shaders declare " + std::to_string(declared));
}

Grid gridFor(uint64_t items, uint32_t groupSize) {
  constexpr uint64_t kMaxX = 65535;
  uint64_t groups = (items + groupSize - 1) / groupSize;
  if (groups == 0) return {};
  if (groups <= kMaxX) return {uint32_t(groups), 1};
  uint64_t y = (groups + kMaxX - 1) / kMaxX;
  uint64_t x = (groups + y - 1) / y;
  return {uint32_t(x), uint32_t(y)};
}

} // namespace pointrast::gpu
