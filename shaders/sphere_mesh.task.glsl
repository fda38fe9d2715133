#version 460
// sphere-mesh-points and sphere-mesh-tris with --task-cull: a task workgroup of 32 invocations tests 4 x 32
// = 128 consecutive spheres of a part with the impostor's own test (near plane, bad values, projected
// bounds outside the image: sphereImpostor().visible, so nothing the mesh stage would draw is dropped)
// and launches ceil(survivors / MESHLET) mesh workgroups, passing the survivors' offsets in index order.
// A meshlet of the mesh stage then holds only visible spheres; an invisible 128 launches nothing.
#extension GL_EXT_mesh_shader : require
#include "sphere_impostor.inc.glsl"
#include "sphere_mesh_payload.inc.glsl"

// Spheres per mesh workgroup of the paired mesh shader (31 or 15).
layout(constant_id = 1) const uint MESHLET = kSphereMeshletLarge;
layout(local_size_x = kSphereTaskGroupSize) in;

const uint kRounds = kSphereTaskSpheres / kSphereTaskGroupSize;
shared uint visibleMasks[kRounds]; // bit i of word r: sphere r * 32 + i of the workgroup's 128 survives

void main() {
  frame = SphereFrameRef(pc.frame).f;
  uint lane = gl_LocalInvocationIndex;
  uint group = pc.firstGroup + gl_WorkGroupID.y * pc.groupsX + gl_WorkGroupID.x;
  uint first = group * kSphereTaskSpheres;
  if (lane < kRounds) visibleMasks[lane] = 0u;
  barrier();
  for (uint r = 0u; r < kRounds; ++r) {
    uint local = first + r * kSphereTaskGroupSize + lane;
    if (local < pc.count && sphereImpostor(local).visible) atomicOr(visibleMasks[r], 1u << lane);
  }
  barrier();
  // Compaction in index order: the slot of a survivor is the number of survivors before it.
  uint survivors = 0u;
  for (uint r = 0u; r < kRounds; ++r) {
    uint mask = visibleMasks[r];
    if ((mask & (1u << lane)) != 0u)
      payload.offsets[survivors + bitCount(mask & ((1u << lane) - 1u))] = r * kSphereTaskGroupSize + lane;
    survivors += bitCount(mask);
  }
  if (lane == 0u) {
    payload.first = first;
    payload.count = survivors;
  }
  EmitMeshTasksEXT((survivors + MESHLET - 1u) / MESHLET, 1u, 1u);
}
