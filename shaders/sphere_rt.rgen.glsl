#version 460
// sphere-rt, ray generation: one ray per pixel center; writes the pixel's visibility word.
#include "sphere_rt.inc.glsl"

layout(location = SPHERE_RT_PAYLOAD_LOCATION) rayPayloadEXT uint64_t word;

// Larger than any view depth a float sphere can have (callers cull |coordinates| >= 3e38).
const float kRayEnd = 3.0e38;

void main() {
  frame = SphereFrameRef(pc.frame).f;
  uvec2 p = gl_LaunchIDEXT.xy;
  // view = [R | T]: the eye is at -R^T T in the particles' frame, and R^T maps the view ray there. R is a
  // rotation, so the world direction has the view ray's length and t keeps meaning view depth; the
  // rounding of this transform only steers traversal (the AABBs are padded for it), never the hit.
  mat3 toWorld = transpose(mat3(frame.view));
  vec3 origin = -(toWorld * frame.view[3].xyz);
  vec3 dir = toWorld * sphereRay(frame.pixelToRay, vec2(p) + 0.5);
  word = kEmptyPixel;
  traceRayEXT(accelerationStructureEXT(pc.tlas), gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, origin, 0.0, dir, kRayEnd,
              SPHERE_RT_PAYLOAD_LOCATION);
  Uint64Array(frame.framebuffer).v[p.y * frame.width + p.x] = word;
}
