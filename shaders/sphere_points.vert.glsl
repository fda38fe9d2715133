#version 460
// sphere-points: one point per sphere (a Vulkan point list), gl_PointSize the larger side of the impostor
// (the sphere's projected bounds, or the camera-aligned square), centered on it, at the depth of the
// sphere's front. A sphere larger than the
// device's largest point is drawn clipped to it (its edge is missing) and counted in frame.counters[0],
// the study's known limit of this pipeline.
#include "sphere_impostor.inc.glsl"

layout(location = 0) flat out vec4 centerRadius;
layout(location = 1) flat out vec4 color;
layout(location = 2) flat out uint index;

void main() {
  frame = SphereFrameRef(pc.frame).f;
  Impostor imp = sphereImpostor(gl_VertexIndex);
  centerRadius = imp.centerRadius;
  color = imp.color;
  index = imp.index;
  gl_PointSize = 1.0;
  if (!imp.visible) {
    gl_Position = kCulledPosition;
    return;
  }
  // Pixels: the NDC extent times W/2 (or H/2).
  vec2 extent = (imp.ndc.zw - imp.ndc.xy) * 0.5 * vec2(frame.width, frame.height);
  float size = max(extent.x, extent.y);
  if (size > frame.maxPointSize) {
    atomicAdd(UintArray(frame.counters).v[0], 1u);
    size = frame.maxPointSize;
  }
  gl_PointSize = size;
  gl_Position = vec4(0.5 * (imp.ndc.xy + imp.ndc.zw), imp.depth, 1.0);
}
