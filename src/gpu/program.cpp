#include "gpu/program.h"

#include <algorithm>

#include "gpu/context.h"
#include "gpu/pipeline_parts.h"
#include "gpu/shader_registry.h"

namespace pointrast::gpu {

ComputeProgram::ComputeProgram(Context& context, const std::string& shaderName,
                               std::initializer_list<SpecConstant> spec)
    : device_(context.device()), name_(shaderName) {
  std::span<const uint32_t> words = findShader(shaderName);
  reflection_ = reflectSpirv(words);
  assertSpecDeclared({&reflection_, 1}, spec);
  ShaderModules modules(device_);
  VkShaderModule module = modules.add(words);
  try {
    layout_ = createPipelineLayout(device_, VK_SHADER_STAGE_COMPUTE_BIT, reflection_.pushConstantSize);
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
  } catch (...) {
    release();
    throw;
  }
}

ComputeProgram::~ComputeProgram() {
  release();
}

void ComputeProgram::release() {
  destroyPipeline(device_, pipeline_, layout_);
}

ComputeProgram::ComputeProgram(ComputeProgram&& other) noexcept {
  *this = std::move(other);
}

ComputeProgram& ComputeProgram::operator=(ComputeProgram&& other) noexcept {
  if (this != &other) {
    release();
    device_ = other.device_;
    layout_ = std::exchange(other.layout_, VK_NULL_HANDLE);
    pipeline_ = std::exchange(other.pipeline_, VK_NULL_HANDLE);
    reflection_ = other.reflection_;
    name_ = other.name_;
  }
  return *this;
}

void ComputeProgram::dispatchRaw(VkCommandBuffer cmd, uint32_t groupsX, uint32_t groupsY, const void* push,
                                 uint32_t size) const {
  if (groupsX == 0 || groupsY == 0) return;
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  if (size) vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, size, push);
  vkCmdDispatch(cmd, groupsX, groupsY, 1);
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
