// Graphics programs (vertex [+ geometry] + fragment) built from embedded SPIR-V, the rasterization-pipeline
// sibling of ComputeProgram. Like it, the layout comes from the modules: one push-constant range of the
// reflected size shared by all stages, no descriptor sets and no vertex input bindings (the vertex shader
// pulls its data by buffer device address with gl_VertexIndex / gl_InstanceIndex), and variants are
// specialization constants named at the call site. Pipelines draw with dynamic rendering (Vulkan 1.3),
// so no render pass objects; viewport and scissor are dynamic state, set with setViewport.
//
//   GraphicsProgram points(ctx, "points_hw.vert", "points_hw.frag", {.depthCompare = VK_COMPARE_OP_GREATER});
//   points.draw(cmd, count, push);  // checks sizeof(push) == the shaders' push-constant block
#pragma once

#include <cassert>
#include <cstdint>
#include <string>
#include <vector>

#include "gpu/program.h"
#include "gpu/spirv_reflect.h"
#include "gpu/vulkan_api.h"

namespace pointrast::gpu {

class Context;

struct GraphicsOptions {
  VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
  VkFormat colorFormat = VK_FORMAT_R8G8B8A8_UNORM;
  VkFormat depthFormat = VK_FORMAT_D32_SFLOAT;   // UNDEFINED: no depth attachment, no depth test
  VkCompareOp depthCompare = VK_COMPARE_OP_LESS; // with depth writes; GREATER for reverse-Z
  // A geometry shader between vertex and fragment shader; empty for none (needs the geometryShader
  // feature, DeviceFeatures::geometryShader).
  std::string geometryShader;
  // Specialization constants, given to every stage (a stage that does not declare an id ignores it).
  std::vector<SpecConstant> spec;
  // A second color attachment (fragment output location 1) when not UNDEFINED, e.g. R32_UINT ids.
  VkFormat secondColorFormat = VK_FORMAT_UNDEFINED;
  // Overestimating conservative rasterization (VK_EXT_conservative_rasterization): every pixel the
  // primitive touches gets a fragment, not only those whose center it covers. Needs
  // DeviceFeatures::conservativeRasterization, and conservativePoints for a point list drawn as points.
  bool conservative = false;
  // Alpha blending of the (first) color attachment: SRC_ALPHA, ONE_MINUS_SRC_ALPHA (overlays, the panel).
  bool blend = false;
  // A mesh pipeline (VK_EXT_mesh_shader, DeviceFeatures::meshShader): the first shader named is a mesh
  // shader instead of a vertex shader, preceded by taskShader unless empty (DeviceFeatures::taskShader).
  // No vertex input or input assembly; draw with drawMeshTasks. `topology` then names the list of the
  // mesh shader's output primitives (points or triangles), for the checks that depend on it.
  bool meshShader = false;
  std::string taskShader;
};

class GraphicsProgram : public Pipeline {
public:
  GraphicsProgram() = default;
  GraphicsProgram(Context& context, const std::string& vertexShader, const std::string& fragmentShader,
                  const GraphicsOptions& options = {});

  const GraphicsOptions& options() const { return options_; }

  // Binds the pipeline, pushes the constants and draws vertexCount vertices of each of instanceCount
  // instances. Must be recorded between vkCmdBeginRendering and vkCmdEndRendering with attachments of
  // options() formats.
  template <class Push>
  void draw(VkCommandBuffer cmd, uint32_t vertexCount, const Push& push, uint32_t instanceCount = 1) const {
    drawRaw(cmd, vertexCount, instanceCount, &push, sizeof(Push));
  }

  // Mesh pipelines: binds, pushes the constants and launches groupsX x groupsY task workgroups (or mesh
  // workgroups without a task shader), between vkCmdBeginRendering and vkCmdEndRendering.
  template <class Push>
  void drawMeshTasks(VkCommandBuffer cmd, uint32_t groupsX, uint32_t groupsY, const Push& push) const {
    drawMeshTasksRaw(cmd, groupsX, groupsY, &push, sizeof(Push));
  }

private:
  void drawMeshTasksRaw(VkCommandBuffer cmd, uint32_t groupsX, uint32_t groupsY, const void* push,
                        uint32_t size) const;
  void drawRaw(VkCommandBuffer cmd, uint32_t vertexCount, uint32_t instanceCount, const void* push,
               uint32_t size) const;
  GraphicsOptions options_;
};

// Viewport (0, 0)-(width, height) with depth range [0, 1], and the same scissor: the dynamic state every
// GraphicsProgram expects before its first draw.
void setViewport(VkCommandBuffer cmd, uint32_t width, uint32_t height);

} // namespace pointrast::gpu
