#include "gpu/graphics.h"

#include <algorithm>
#include <span>
#include <utility>

#include "gpu/context.h"
#include "gpu/pipeline_parts.h"
#include "gpu/shader_registry.h"

namespace pointrast::gpu {

GraphicsProgram::GraphicsProgram(Context& context, const std::string& vertexShader,
                                 const std::string& fragmentShader, const GraphicsOptions& options)
    : Pipeline(context.device(),
               (options.taskShader.empty() ? "" : options.taskShader + " + ") + vertexShader + " + " +
                   (options.geometryShader.empty() ? "" : options.geometryShader + " + ") + fragmentShader),
      options_(options) {
  bool geometry = !options.geometryShader.empty();
  bool mesh = options.meshShader;
  assert((!mesh || (!geometry && context.features().meshShader)) && "a mesh pipeline the device cannot make");
  assert((options.taskShader.empty() || (mesh && context.features().taskShader)) &&
         "a task shader belongs to a mesh pipeline of a device with task shaders");
  // Stages in pipeline order: vertex, [geometry,] fragment; or [task,] mesh, fragment.
  std::vector<std::pair<VkShaderStageFlagBits, std::span<const uint32_t>>> sources;
  if (!options.taskShader.empty())
    sources.push_back({VK_SHADER_STAGE_TASK_BIT_EXT, findShader(options.taskShader)});
  sources.push_back(
      {mesh ? VK_SHADER_STAGE_MESH_BIT_EXT : VK_SHADER_STAGE_VERTEX_BIT, findShader(vertexShader)});
  if (geometry) sources.push_back({VK_SHADER_STAGE_GEOMETRY_BIT, findShader(options.geometryShader)});
  sources.push_back({VK_SHADER_STAGE_FRAGMENT_BIT, findShader(fragmentShader)});
  std::vector<SpirvReflection> reflections;
  for (const auto& [stage, words] : sources) {
    reflections.push_back(reflectSpirv(words));
    uint32_t size = reflections.back().pushConstantSize;
    // Every stage sees the same block from offset 0 (one struct from shared.h), or declares none.
    assert((size == 0 || pushConstantSize_ == 0 || size == pushConstantSize_) &&
           "the stages declare different push-constant blocks");
    pushConstantSize_ = std::max(pushConstantSize_, size);
    pushStages_ |= stage;
  }
  // Without maintenance5 a point list rasterizes with an undefined size unless the last vertex stage
  // writes gl_PointSize (a geometry shader turns points into its own output primitives).
  const SpirvReflection& firstVertexStage = reflections[options.taskShader.empty() ? 0 : 1];
  assert(
      (options.topology != VK_PRIMITIVE_TOPOLOGY_POINT_LIST || geometry || firstVertexStage.usesPointSize) &&
      "a point-list pipeline needs a vertex shader that writes gl_PointSize");
  assert((!mesh || firstVertexStage.executionModel == kSpirvMesh) && "meshShader names no mesh shader");
  assert((!mesh || (firstVertexStage.outputTopology == kSpirvOutputPoints) ==
                       (options.topology == VK_PRIMITIVE_TOPOLOGY_POINT_LIST)) &&
         "topology does not name the mesh shader's output primitive");
  (void)firstVertexStage;
  assertSpecDeclared(reflections, options.spec);
  Specialization specialization(options.spec);

  ShaderModules modules(device_);
  for (const auto& source : sources)
    modules.add(source.second);
  layout_ = createPipelineLayout(device_, pushStages_, pushConstantSize_);

  std::vector<VkPipelineShaderStageCreateInfo> stages(sources.size(),
                                                      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO});
  for (size_t i = 0; i < sources.size(); ++i) {
    stages[i].stage = sources[i].first;
    stages[i].module = modules[i];
    stages[i].pName = "main";
    stages[i].pSpecializationInfo = specialization.info();
  }

  VkPipelineVertexInputStateCreateInfo vertexInput{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  VkPipelineInputAssemblyStateCreateInfo assembly{
      VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = options.topology;
  VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  viewport.viewportCount = 1;
  viewport.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;
  raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  raster.lineWidth = 1.0f;
  VkPipelineRasterizationConservativeStateCreateInfoEXT conservative{
      VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_CONSERVATIVE_STATE_CREATE_INFO_EXT};
  conservative.conservativeRasterizationMode = VK_CONSERVATIVE_RASTERIZATION_MODE_OVERESTIMATE_EXT;
  conservative.extraPrimitiveOverestimationSize = 0.0f; // the device's own overestimation suffices
  if (options.conservative) {
    assert(context.features().conservativeRasterization &&
           (context.features().conservativePoints || geometry ||
            options.topology != VK_PRIMITIVE_TOPOLOGY_POINT_LIST) &&
           "conservative rasterization the device does not support");
    raster.pNext = &conservative;
  }
  VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  depth.depthTestEnable = options.depthFormat != VK_FORMAT_UNDEFINED;
  depth.depthWriteEnable = depth.depthTestEnable;
  depth.depthCompareOp = options.depthCompare;
  VkFormat colorFormats[2] = {options.colorFormat, options.secondColorFormat};
  uint32_t colorCount = options.secondColorFormat == VK_FORMAT_UNDEFINED ? 1 : 2;
  VkPipelineColorBlendAttachmentState blendAttachments[2] = {};
  for (VkPipelineColorBlendAttachmentState& b : blendAttachments)
    b.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                       VK_COLOR_COMPONENT_A_BIT;
  if (options.blend) {
    VkPipelineColorBlendAttachmentState& b = blendAttachments[0];
    b.blendEnable = VK_TRUE;
    b.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
    b.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    b.colorBlendOp = VK_BLEND_OP_ADD;
    b.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    b.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    b.alphaBlendOp = VK_BLEND_OP_ADD;
  }
  VkPipelineColorBlendStateCreateInfo blend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  blend.attachmentCount = colorCount;
  blend.pAttachments = blendAttachments;
  VkDynamicState dynamicStates[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dynamic.dynamicStateCount = 2;
  dynamic.pDynamicStates = dynamicStates;
  VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  rendering.colorAttachmentCount = colorCount;
  rendering.pColorAttachmentFormats = colorFormats;
  rendering.depthAttachmentFormat = options.depthFormat;

  VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, &rendering};
  info.stageCount = uint32_t(stages.size());
  info.pStages = stages.data();
  info.pVertexInputState = mesh ? nullptr : &vertexInput; // ignored with a mesh shader: none given
  info.pInputAssemblyState = mesh ? nullptr : &assembly;
  info.pViewportState = &viewport;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &blend;
  info.pDynamicState = &dynamic;
  info.layout = layout_;
  VK_CHECK(vkCreateGraphicsPipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_));
  context.setName(VK_OBJECT_TYPE_PIPELINE, uint64_t(pipeline_), name_);
}

void GraphicsProgram::drawRaw(VkCommandBuffer cmd, uint32_t vertexCount, uint32_t instanceCount,
                              const void* push, uint32_t size) const {
  bind(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, push, size);
  if (vertexCount == 0 || instanceCount == 0) return;
  vkCmdDraw(cmd, vertexCount, instanceCount, 0, 0);
}

void GraphicsProgram::drawMeshTasksRaw(VkCommandBuffer cmd, uint32_t groupsX, uint32_t groupsY,
                                       const void* push, uint32_t size) const {
  assert(options_.meshShader && vkCmdDrawMeshTasksEXT && "drawMeshTasks needs a mesh pipeline");
  bind(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, push, size);
  if (groupsX == 0 || groupsY == 0) return;
  vkCmdDrawMeshTasksEXT(cmd, groupsX, groupsY, 1);
}

void setViewport(VkCommandBuffer cmd, uint32_t width, uint32_t height) {
  VkViewport viewport{0.0f, 0.0f, float(width), float(height), 0.0f, 1.0f};
  VkRect2D scissor{{0, 0}, {width, height}};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

} // namespace pointrast::gpu
