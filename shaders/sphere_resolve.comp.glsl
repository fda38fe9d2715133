#version 460
// sphere-compute, resolve: visibility buffer -> shaded RGBA8 image. The winning word holds the view depth
// of the hit and the particle index; the sphere is fetched again and the hit point rebuilt on the pixel's
// ray at exactly the depth the raster pass computed and compared (re-running the intersection would give
// the same number, at the cost of a square root), and shaded with the common headlight model.
#include "sphere_particles.inc.glsl"
#include "grid.inc.glsl"

layout(local_size_x = kPixelGroupSize) in;
layout(push_constant) uniform Push { SpherePush pc; };

void main() {
  uint i = linearInvocation(pc.groupsX, kPixelGroupSize);
  frame = SphereFrameRef(pc.frame).f;
  if (i >= frame.width * frame.height) return;
  uint64_t word = Uint64Array(frame.framebuffer).v[i];
  uint color = frame.background;
  if (word != kEmptyPixel) {
    Sphere s = sphereByIndex(uint(word));
    vec3 center = (frame.view * vec4(s.center, 1.0)).xyz;
    vec3 dir = sphereRay(frame.pixelToRay, vec2(i % frame.width, i / frame.width) + 0.5);
    color = packUnorm4x8(shadeSphere(center, dir, uintBitsToFloat(uint(word >> 32)), s.color));
  }
  UintArray(frame.image).v[i] = color;
}
