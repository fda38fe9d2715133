#version 460
// sphere-rt, before the acceleration structure build: one VkAabbPositionsKHR per particle of a part (the
// bottom-level structure's AABB geometry), one thread per particle, in the particles' frame (world axes,
// relative to their origin) and whatever the layout (LAYOUT, as every sphere shader).
//
// The box is the sphere's, padded: the ray that traverses the structure is the view ray rotated into
// this frame (sphere_rt.rgen.glsl), while the intersection shader decides in view space, and the two
// differ by the rounding of the transform (a few ulps of the coordinates). The sphere touches its box
// only at six points, where a ray could hit the sphere in view space yet miss the unpadded box; the
// padding (2^-12 of the radius plus 2^-18, 32 ulps, of the largest coordinate) closes
// that gap at the cost of a few more intersection-shader calls around those points.
//
// A particle every sphere method culls for its values (non-finite coordinates, radius not a positive
// finite number: viewSphere) gets an inactive box (min.x = NaN), which Vulkan ignores in the build.
#include "sphere_particles.inc.glsl"
#include "grid.inc.glsl"

layout(local_size_x = kSphereGroupSize) in;
layout(push_constant) uniform Push { SphereAabbPush pc; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer AabbArray { float v[]; };

void main() {
  uint i = linearInvocation(pc.groupsX, kSphereGroupSize);
  if (i >= pc.count) return;
  frame = SphereFrameRef(pc.frame).f;
  Sphere s = loadSphere(pc.particles, pc.count, i);
  bool valid = finiteSphere(s.center, s.radius);
  vec3 a = abs(s.center);
  float extent = s.radius * (1.0 + 1.0 / 4096.0) + max(a.x, max(a.y, a.z)) * (1.0 / 262144.0);
  vec3 lo = s.center - extent, hi = s.center + extent;
  if (!valid) lo.x = uintBitsToFloat(0x7FC00000u); // quiet NaN: an inactive AABB
  AabbArray out6 = AabbArray(pc.aabbs);
  out6.v[6 * i] = lo.x;
  out6.v[6 * i + 1] = lo.y;
  out6.v[6 * i + 2] = lo.z;
  out6.v[6 * i + 3] = hi.x;
  out6.v[6 * i + 4] = hi.y;
  out6.v[6 * i + 5] = hi.z;
}
