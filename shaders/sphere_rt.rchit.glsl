#version 460
// sphere-rt, closest hit: sphere-compute's visibility word of the nearest sphere (the reported t is its
// view depth; the particle is the committed primitive of the committed instance, a piece of a part).
#include "sphere_rt.inc.glsl"
#include "sphere_rt_hit.inc.glsl"

layout(location = SPHERE_RT_PAYLOAD_LOCATION) rayPayloadInEXT uint64_t word;

void main() {
  uint part = uint(gl_InstanceCustomIndexEXT) >> kSphereRtPieceBits;
  uint index = part * SphereFrameRef(pc.frame).f.partCapacity + sphereRtLocalIndex();
  word = (uint64_t(floatBitsToUint(gl_HitTEXT)) << 32) | uint64_t(index);
}
