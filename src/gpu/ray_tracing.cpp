#include "gpu/ray_tracing.h"

#include <algorithm>
#include <cstring>
#include <span>
#include <utility>

#include "base/error.h"
#include "gpu/context.h"
#include "gpu/pipeline_parts.h"
#include "gpu/shader_registry.h"
#include "gpu/spirv_reflect.h"

namespace pointrast::gpu {

ShaderBindingTableLayout shaderBindingTableLayout(uint32_t handleSize, uint32_t handleAlignment,
                                                  uint32_t baseAlignment, uint32_t missGroups,
                                                  uint32_t hitGroups) {
  assert(handleSize > 0);
  ShaderBindingTableLayout t;
  t.stride = alignUp(handleSize, handleAlignment);
  t.rayGenOffset = 0;
  t.rayGenSize = t.stride;
  t.missOffset = alignUp(t.rayGenOffset + t.rayGenSize, baseAlignment);
  t.missSize = t.stride * missGroups;
  t.hitOffset = alignUp(t.missOffset + t.missSize, baseAlignment);
  t.hitSize = t.stride * hitGroups;
  t.size = t.hitOffset + t.hitSize;
  return t;
}

AccelerationStructure::AccelerationStructure(Context& context, VkAccelerationStructureTypeKHR type,
                                             uint64_t size, const std::string& name)
    : device_(context.device()), storage_(context, size,
                                          VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                                              VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                          MemoryKind::Device, name + " storage") {
  assert(context.features().rayTracing && vkCreateAccelerationStructureKHR);
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.buffer = storage_.handle();
  info.offset = 0; // a multiple of 256, as required
  info.size = size;
  info.type = type;
  VK_CHECK(vkCreateAccelerationStructureKHR(device_, &info, nullptr, &handle_));
  VkAccelerationStructureDeviceAddressInfoKHR addressInfo{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  addressInfo.accelerationStructure = handle_;
  address_ = vkGetAccelerationStructureDeviceAddressKHR(device_, &addressInfo);
  context.setName(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, uint64_t(handle_), name);
}

AccelerationStructure::~AccelerationStructure() {
  release();
}

void AccelerationStructure::release() {
  if (deviceFaulted()) return; // the GPU may still use it: leave it to process exit
  if (handle_) vkDestroyAccelerationStructureKHR(device_, handle_, nullptr);
  handle_ = VK_NULL_HANDLE;
  address_ = 0;
}

AccelerationStructure::AccelerationStructure(AccelerationStructure&& other) noexcept {
  *this = std::move(other);
}

AccelerationStructure& AccelerationStructure::operator=(AccelerationStructure&& other) noexcept {
  if (this != &other) {
    release(); // the structure before its buffer
    device_ = other.device_;
    storage_ = std::move(other.storage_);
    handle_ = std::exchange(other.handle_, VK_NULL_HANDLE);
    address_ = std::exchange(other.address_, 0);
  }
  return *this;
}

ScratchBuffer::ScratchBuffer(Context& context, uint64_t size) : size_(size) {
  uint64_t alignment = std::max<uint64_t>(
      context.accelerationStructureProperties().minAccelerationStructureScratchOffsetAlignment, 1);
  // Storage-buffer usage and a device address are what a build's scratch needs (kBufferUsage has both).
  buffer_ =
      Buffer(context, size + alignment, kBufferUsage, MemoryKind::Device, "acceleration structure scratch");
  alignedAddress_ = alignUp(buffer_.address(), alignment);
}

RayTracingProgram::RayTracingProgram(Context& context, const RayTracingShaders& shaders,
                                     std::vector<SpecConstant> spec)
    : Pipeline(context.device(), shaders.rayGen + " + " + shaders.miss + " + " + shaders.intersection +
                                     " + " + shaders.closestHit) {
  assert(context.features().rayTracing && vkCreateRayTracingPipelinesKHR);
  // Stage order = the indices the shader groups name.
  enum { kRayGen, kMiss, kIntersection, kClosestHit, kStages };
  const std::pair<VkShaderStageFlagBits, const std::string*> sources[kStages] = {
      {VK_SHADER_STAGE_RAYGEN_BIT_KHR, &shaders.rayGen},
      {VK_SHADER_STAGE_MISS_BIT_KHR, &shaders.miss},
      {VK_SHADER_STAGE_INTERSECTION_BIT_KHR, &shaders.intersection},
      {VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, &shaders.closestHit}};
  std::vector<SpirvReflection> reflections;
  for (const auto& [stage, name] : sources) {
    reflections.push_back(reflectSpirv(findShader(*name)));
    uint32_t size = reflections.back().pushConstantSize;
    assert((size == 0 || pushConstantSize_ == 0 || size == pushConstantSize_) &&
           "the stages declare different push-constant blocks");
    pushConstantSize_ = std::max(pushConstantSize_, size);
    if (size) pushStages_ |= stage;
  }
  assertSpecDeclared(reflections, spec);
  Specialization specialization(spec);

  const VkPhysicalDeviceRayTracingPipelinePropertiesKHR& limits = context.rayTracingProperties();
  ShaderBindingTableLayout table = shaderBindingTableLayout(
      limits.shaderGroupHandleSize, limits.shaderGroupHandleAlignment, limits.shaderGroupBaseAlignment, 1, 1);
  if (table.stride > limits.maxShaderGroupStride)
    throw UnsupportedError("the device's largest shader group stride (" +
                           std::to_string(limits.maxShaderGroupStride) + ") is below its handle size");

  ShaderModules modules(device_);
  for (const auto& source : sources)
    modules.add(findShader(*source.second));
  layout_ = createPipelineLayout(device_, pushStages_, pushConstantSize_);

  VkPipelineShaderStageCreateInfo stages[kStages];
  for (uint32_t i = 0; i < kStages; ++i) {
    stages[i] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stages[i].stage = sources[i].first;
    stages[i].module = modules[i];
    stages[i].pName = "main";
    stages[i].pSpecializationInfo = specialization.info();
  }
  // Groups (the order of their handles in the table): ray generation, miss, one procedural hit group.
  VkRayTracingShaderGroupCreateInfoKHR groups[3];
  for (VkRayTracingShaderGroupCreateInfoKHR& g : groups) {
    g = {VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
    g.generalShader = g.closestHitShader = g.anyHitShader = g.intersectionShader = VK_SHADER_UNUSED_KHR;
  }
  groups[0].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
  groups[0].generalShader = kRayGen;
  groups[1].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
  groups[1].generalShader = kMiss;
  groups[2].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
  groups[2].intersectionShader = kIntersection;
  groups[2].closestHitShader = kClosestHit;
  VkRayTracingPipelineCreateInfoKHR info{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  info.stageCount = kStages;
  info.pStages = stages;
  info.groupCount = 3;
  info.pGroups = groups;
  info.maxPipelineRayRecursionDepth = 1; // rays are traced from the ray generation shader only
  info.layout = layout_;
  VK_CHECK(
      vkCreateRayTracingPipelinesKHR(device_, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_));
  context.setName(VK_OBJECT_TYPE_PIPELINE, uint64_t(pipeline_), name_);

  // The table: handles copied to their records, in device-local memory whose start is aligned to
  // shaderGroupBaseAlignment (a buffer's address need not be, so it is allocated that much larger).
  uint32_t handleSize = limits.shaderGroupHandleSize;
  std::vector<uint8_t> handles(3 * size_t(handleSize));
  VK_CHECK(vkGetRayTracingShaderGroupHandlesKHR(device_, pipeline_, 0, 3, handles.size(), handles.data()));
  uint64_t base = std::max<uint64_t>(limits.shaderGroupBaseAlignment, 1);
  table_ = Buffer(context, table.size + base,
                  VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
                      VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                  MemoryKind::Device, "shader binding table");
  uint64_t start = alignUp(table_.address(), base);
  uint64_t offset = start - table_.address();
  Buffer staging(context, table.size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryKind::Upload,
                 "shader binding table staging");
  auto* bytes = static_cast<uint8_t*>(staging.mapped());
  std::memset(bytes, 0, table.size);
  std::memcpy(bytes + table.rayGenOffset, handles.data() + 0 * handleSize, handleSize);
  std::memcpy(bytes + table.missOffset, handles.data() + 1 * handleSize, handleSize);
  std::memcpy(bytes + table.hitOffset, handles.data() + 2 * handleSize, handleSize);
  context.submitAndWait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, offset, table.size};
    vkCmdCopyBuffer(cmd, staging.handle(), table_.handle(), 1, &region);
    fullBarrier(cmd); // the copy before any later trace reads the table (the barrier's scope reaches past
                      // this submission)
  });
  rayGen_ = {start + table.rayGenOffset, table.stride, table.rayGenSize};
  miss_ = {start + table.missOffset, table.stride, table.missSize};
  hit_ = {start + table.hitOffset, table.stride, table.hitSize};
  callable_ = {0, 0, 0};
}

void RayTracingProgram::traceRaysRaw(VkCommandBuffer cmd, uint32_t width, uint32_t height, const void* push,
                                     uint32_t size) const {
  bind(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, push, size);
  if (width == 0 || height == 0) return;
  vkCmdTraceRaysKHR(cmd, &rayGen_, &miss_, &hit_, &callable_, width, height, 1);
}

} // namespace pointrast::gpu
