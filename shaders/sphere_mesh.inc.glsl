// The mesh stage of sphere-mesh-points and sphere-mesh-tris (VK_EXT_mesh_shader): a workgroup takes a
// meshlet of MESHLET spheres, one invocation each, builds each sphere's impostor exactly as the vertex
// pipelines do (sphere_impostor.inc.glsl) and emits the visible ones, compacted in index order, as
//   MESH_TRIS 0  one point per sphere, gl_PointSize the larger side of the projected bounds (clamped to the
//                device's largest point and counted in frame.counters[0], as sphere-points does), or
//   MESH_TRIS 1  a screen-aligned quad over the bounds as two triangles (4 vertices, 2 primitives),
// for sphere_impostor.frag.glsl, the fragment stage of every rasterization sphere pipeline.
// MESH_TASK 1: the meshlet is a slice of the survivors a task workgroup passed in its payload
// (sphere_mesh.task.glsl); 0: the meshlet is MESHLET consecutive spheres of the part.
//
// The entry files define MESHLET, MESH_TRIS and MESH_TASK: the output topology and the maximal vertex
// and primitive counts are literal execution modes in SPIR-V, not specialization constants, and a
// driver sizes a workgroup's output memory from the declared maxima, so a 15-sphere meshlet must not
// declare the outputs of 31.
//
// Output budget. Per vertex: gl_Position (4 components) + centerRadius (4) + color (4) + index (1) = 13
// of the >= 128 output components every VK_EXT_mesh_shader device has (+ gl_PointSize for points).
// mesh-tris with 31 spheres declares 31 x 4 = 124 vertices and 31 x 2 = 62 triangles (limits: >= 256
// each); its outputs take about 124 x 13 x 4 B + 62 x 3 x 4 B = 7.0 KiB of the >= 32 KiB
// maxMeshOutputMemorySize (7.3 KiB with vertices and primitives rounded up to NVIDIA's granularity of
// 32). mesh-points with 31 spheres: 31 vertices, 31 points. 31 and 15 spheres per meshlet (31 quads = 124
// vertices, 15 quads = 60) are the study's sizes (Gralka et al. 2023), chosen there for the output
// limits of its NV_mesh_shader implementation; they are kept for comparability, although
// VK_EXT_mesh_shader's guaranteed limits would also take 32.
// sphere_mesh.cpp checks the device's limits against the declared counts (meshletFits) before drawing.
// The workgroup is MESHLET invocations (<= 32: one subgroup on NVIDIA, whose preferred mesh workgroup is
// 32), so one mask word compacts it.
#extension GL_EXT_mesh_shader : require
#include "sphere_impostor.inc.glsl"
#if MESH_TASK
#include "sphere_mesh_payload.inc.glsl"
#endif

layout(local_size_x = MESHLET) in;
#if MESH_TRIS
layout(triangles, max_vertices = 4 * MESHLET, max_primitives = 2 * MESHLET) out;
#else
layout(points, max_vertices = MESHLET, max_primitives = MESHLET) out;
#endif

// The fragment stage's inputs (sphere_impostor.frag.glsl), per vertex.
layout(location = 0) flat out vec4 centerRadius[];
layout(location = 1) flat out vec4 color[];
layout(location = 2) flat out uint index[];

shared uint visibleMask; // bit i: invocation i emits its sphere

void main() {
  frame = SphereFrameRef(pc.frame).f;
  uint lane = gl_LocalInvocationIndex;
#if MESH_TASK
  uint slice = gl_WorkGroupID.x * MESHLET + lane;
  bool mine = slice < payload.count;
  uint local = mine ? payload.first + payload.offsets[slice] : 0u;
#else
  uint group = pc.firstGroup + gl_WorkGroupID.y * pc.groupsX + gl_WorkGroupID.x;
  uint local = group * MESHLET + lane;
  bool mine = local < pc.count; // the last meshlet of a part, and the spare groups of a 2D grid
#endif
  Impostor imp;
  imp.visible = false;
  if (mine) imp = sphereImpostor(local);

  // Compaction in index order (deterministic, unlike an atomic counter): a culled sphere leaves no hole
  // in the outputs, and equal depths resolve as in the vertex pipelines, to the first drawn.
  if (lane == 0u) visibleMask = 0u;
  barrier();
  if (imp.visible) atomicOr(visibleMask, 1u << lane);
  barrier();
  uint mask = visibleMask;
  uint emitted = bitCount(mask);
#if MESH_TRIS
  SetMeshOutputsEXT(4u * emitted, 2u * emitted);
#else
  SetMeshOutputsEXT(emitted, emitted);
#endif
  if (!imp.visible) return;
  uint slot = bitCount(mask & ((1u << lane) - 1u));

#if MESH_TRIS
  // Corners: bit 0 = right (x1), bit 1 = bottom (y1); triangles (0, 1, 2) and (2, 1, 3) as in
  // sphere_quads.vert.glsl.
  uint first = 4u * slot;
  for (uint corner = 0u; corner < 4u; ++corner) {
    gl_MeshVerticesEXT[first + corner].gl_Position =
        vec4((corner & 1u) != 0u ? imp.ndc.z : imp.ndc.x, (corner & 2u) != 0u ? imp.ndc.w : imp.ndc.y,
             imp.depth, 1.0);
    centerRadius[first + corner] = imp.centerRadius;
    color[first + corner] = imp.color;
    index[first + corner] = imp.index;
  }
  gl_PrimitiveTriangleIndicesEXT[2u * slot] = uvec3(first, first + 1u, first + 2u);
  gl_PrimitiveTriangleIndicesEXT[2u * slot + 1u] = uvec3(first + 2u, first + 1u, first + 3u);
#else
  // Pixels: the NDC extent times W/2 (or H/2), as in sphere_points.vert.glsl.
  vec2 extent = (imp.ndc.zw - imp.ndc.xy) * 0.5 * vec2(frame.width, frame.height);
  float size = max(extent.x, extent.y);
  if (size > frame.maxPointSize) {
    atomicAdd(UintArray(frame.counters).v[0], 1u);
    size = frame.maxPointSize;
  }
  gl_MeshVerticesEXT[slot].gl_Position = vec4(0.5 * (imp.ndc.xy + imp.ndc.zw), imp.depth, 1.0);
  gl_MeshVerticesEXT[slot].gl_PointSize = size;
  centerRadius[slot] = imp.centerRadius;
  color[slot] = imp.color;
  index[slot] = imp.index;
  gl_PrimitivePointIndicesEXT[slot] = slot;
#endif
}
