#version 460
// sphere-rt, closest hit: sphere-compute's visibility word of the nearest sphere (the reported t is its
// view depth; the particle is the committed primitive of the committed instance, its part).
#include "sphere_rt.inc.glsl"

layout(location = SPHERE_RT_PAYLOAD_LOCATION) rayPayloadInEXT uint64_t word;

void main() {
  uint index = uint(gl_InstanceCustomIndexEXT) * SphereFrameRef(pc.frame).f.partCapacity + uint(gl_PrimitiveID);
  word = (uint64_t(floatBitsToUint(gl_HitTEXT)) << 32) | uint64_t(index);
}
