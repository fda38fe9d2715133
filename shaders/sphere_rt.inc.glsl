// sphere-rt (VK_KHR_ray_tracing_pipeline): the stages' shared declarations. One ray per pixel center, in
// the particles' frame (world axes, relative to their origin): the pixel's view ray of every sphere
// method (sphere_shade.inc.glsl) rotated into that frame, so its parameter t is still the view depth.
// The acceleration structure holds one AABB per sphere (sphere_rt_aabbs.comp.glsl); the intersection
// shader ray-casts the sphere in view space with the shared intersection, exactly as sphere-compute does,
// and reports the hit at t = its view depth. The closest hit then writes sphere-compute's visibility
// word (floatBits(depth) << 32 | particle index) and sphere_resolve.comp.glsl shades it.
//
// The TLAS is passed by device address (accelerationStructureEXT(uint64_t)), so like every other
// pointrast pipeline this one has no descriptor sets, only push constants.
#extension GL_EXT_ray_tracing : require
#include "sphere_particles.inc.glsl"

layout(push_constant) uniform Push { SphereRtPush pc; };

// Payload: the visibility word of the pixel, kEmptyPixel when the ray hits nothing.
#define SPHERE_RT_PAYLOAD_LOCATION 0
