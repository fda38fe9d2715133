#version 460
// sphere-geom, vertex stage: one vertex per sphere; the impostor's NDC bounds travel in gl_Position to
// sphere_geom.geom.glsl, which expands them into a quad (or nothing for a culled sphere).
#include "sphere_impostor.inc.glsl"

layout(location = 0) flat out vec4 centerRadius;
layout(location = 1) flat out vec4 color;
layout(location = 2) flat out uint index;
layout(location = 3) flat out float depth;

void main() {
  frame = SphereFrameRef(pc.frame).f;
  Impostor imp = sphereImpostor(gl_VertexIndex);
  centerRadius = imp.centerRadius;
  color = imp.color;
  index = imp.index;
  depth = imp.depth;
  gl_Position = imp.ndc;
}
