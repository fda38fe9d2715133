#version 460
// sphere-rt, intersection: the ray of this pixel against the sphere of this AABB, computed in view space
// with the shared robust intersection (sphere_shade.inc.glsl) and the same culling as every sphere
// method (viewSphere: crossing the near plane or bad values): the depth sphere-compute finds, by the same
// float operations. The hit is reported at t = view depth, which is the ray's own parameter (see
// sphere_rt.rgen.glsl), so traversal keeps the nearest. No hit attribute: the closest-hit shader finds the
// particle from the committed instance and primitive (an attribute written before a report that traversal
// then rejects came out as another sphere's index on Mesa 25's lavapipe).
#include "sphere_rt.inc.glsl"
#include "sphere_rt_hit.inc.glsl"

void main() {
  frame = SphereFrameRef(pc.frame).f;
  // One instance per piece of a part (custom index = part << kSphereRtPieceBits | piece), one AABB per
  // particle of the piece (primitive = index in the piece).
  SpherePartRef part = PartTable(frame.parts).v[gl_InstanceCustomIndexEXT >> kSphereRtPieceBits];
  Sphere s = loadSphere(part.address, part.count, sphereRtLocalIndex());
  vec3 center;
  if (!viewSphere(s, center)) return;
  float depth;
  if (!intersectSphere(center, s.radius, sphereRay(frame.pixelToRay, vec2(gl_LaunchIDEXT.xy) + 0.5), depth))
    return;
  reportIntersectionEXT(depth, 0u);
}
