#version 460
// sphere-triangles and sphere-strip: a screen-aligned quad per sphere over its projected bounds, at the
// depth of its front. QUAD picks how the quad is drawn:
//   kSphereQuadTriangles  a triangle list, 6 vertices per sphere (every vertex redoes the sphere's setup)
//   kSphereQuadStrip      one instance per sphere of a 4-vertex triangle strip
#include "sphere_impostor.inc.glsl"

layout(constant_id = 1) const uint QUAD = kSphereQuadTriangles;
layout(location = 0) flat out vec4 centerRadius;
layout(location = 1) flat out vec4 color;
layout(location = 2) flat out uint index;

// Corners of the two triangles (0, 1, 2) and (2, 1, 3) of a quad: bit 0 = right, bit 1 = bottom.
const uint kTriangleCorners[6] = uint[6](0, 1, 2, 2, 1, 3);

void main() {
  frame = SphereFrameRef(pc.frame).f;
  uint local = QUAD == kSphereQuadStrip ? gl_InstanceIndex : gl_VertexIndex / 6;
  uint corner = QUAD == kSphereQuadStrip ? gl_VertexIndex : kTriangleCorners[gl_VertexIndex % 6];
  Impostor imp = sphereImpostor(local);
  centerRadius = imp.centerRadius;
  color = imp.color;
  index = imp.index;
  gl_Position = imp.visible ? vec4((corner & 1u) != 0u ? imp.ndc.z : imp.ndc.x,
                                   (corner & 2u) != 0u ? imp.ndc.w : imp.ndc.y, imp.depth, 1.0)
                            : kCulledPosition;
}
