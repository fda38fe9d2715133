// sphere-mesh-points and sphere-mesh-tris (VK_EXT_mesh_shader; sphere_mesh.cpp, shaders/sphere_mesh*.glsl):
// the host-side arithmetic of the mesh pipelines, apart so that it is tested on devices without mesh
// shaders.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gpu/shared_types.h"
#include "gpu/vulkan_api.h"

namespace pointrast {

// One vkCmdDrawMeshTasksEXT: groupsX x groupsY workgroups, the first of them being workgroup `firstGroup`
// of the part (SpherePush::firstGroup; a shader's workgroup is firstGroup + y * groupsX + x).
struct MeshDraw {
  uint32_t firstGroup = 0;
  uint32_t groupsX = 0, groupsY = 0;
};

// The draws that launch ceil(count / spheresPerGroup) workgroups (mesh workgroups of a meshlet each, or
// task workgroups of kSphereTaskSpheres each) within the device's limits: at most maxTotal workgroups per
// draw (maxMeshWorkGroupTotalCount, or the task one) in a grid of at most maxX x maxY
// (maxMeshWorkGroupCount[0], [1]). Every draw is an exact rectangle, so no workgroup is launched twice
// and none past the last; full-size rectangles first, then at most one rectangle of whole rows and one
// partial row. Empty for count 0. Precondition: every limit and spheresPerGroup > 0, and the part's last
// sphere index fits 32 bits with a workgroup to spare.
std::vector<MeshDraw> planMeshDraws(uint64_t count, uint32_t spheresPerGroup, uint32_t maxTotal,
                                    uint32_t maxX, uint32_t maxY);

// Output components per vertex of the mesh shaders: gl_Position 4 + centerRadius 4 + color 4 + index 1
// (+ gl_PointSize for points).
constexpr uint32_t kMeshVertexComponents = 13;
// Bytes of the task payload (SphereMeshPayload: first, count, 128 offsets) and of the shared memory of
// the task (4 visibility masks) and mesh (1 mask) stages.
constexpr uint32_t kMeshPayloadBytes = 8 + 4 * shared::kSphereTaskSpheres;
constexpr uint32_t kTaskSharedBytes = 4 * (shared::kSphereTaskSpheres / shared::kSphereTaskGroupSize);
constexpr uint32_t kMeshSharedBytes = 4;

// Whether the device's mesh-shader limits take the pipeline of `meshlet` spheres per workgroup drawn as
// points or as quads (4 vertices, 2 triangles each), with or without the culling task shader; why: the
// first limit that does not hold, as "maxMeshOutputVertices is 64, the pipeline declares 124".
bool meshletFits(const VkPhysicalDeviceMeshShaderPropertiesEXT& limits, uint32_t meshlet, bool points,
                 bool task, std::string* why);

// Declared maxima of the mesh shader for a meshlet (they must equal the shaders' OutputVertices and
// OutputPrimitivesEXT; the tests check the embedded SPIR-V).
constexpr uint32_t meshOutputVertices(uint32_t meshlet, bool points) {
  return points ? meshlet : 4 * meshlet;
}
constexpr uint32_t meshOutputPrimitives(uint32_t meshlet, bool points) {
  return points ? meshlet : 2 * meshlet;
}
// The embedded mesh shader of a variant: "sphere_mesh_tris31_task.mesh".
std::string meshShaderName(uint32_t meshlet, bool points, bool task);

} // namespace pointrast
