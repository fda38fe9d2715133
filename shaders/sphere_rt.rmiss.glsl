#version 460
// sphere-rt, miss: no sphere on this pixel's ray.
#include "sphere_rt.inc.glsl"

layout(location = SPHERE_RT_PAYLOAD_LOCATION) rayPayloadInEXT uint64_t word;

void main() {
  word = kEmptyPixel;
}
