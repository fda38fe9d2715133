// Helpers of the resolve stage's passes (shared.h, "The resolve stage"): 16 x 16 tiles of pixels, words
// read from PostPush::source with its pitch.
#include "common.inc.glsl"

layout(local_size_x = kPostTile, local_size_y = kPostTile) in;
layout(push_constant) uniform Push { PostPush pc; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer Words { uint64_t v[]; };

// This invocation's pixel; false past the image's right or bottom edge.
bool postPixel(out ivec2 p) {
  p = ivec2(gl_GlobalInvocationID.xy);
  return p.x < int(pc.width) && p.y < int(pc.height);
}

bool insideImage(ivec2 q) {
  return q.x >= 0 && q.y >= 0 && q.x < int(pc.width) && q.y < int(pc.height);
}

uint64_t sourceWord(ivec2 q) {
  return Words(pc.source).v[uint(q.y) * pc.sourcePitch + uint(q.x)];
}

// Linear depth of a non-empty word (positive, so its IEEE bits order like the float).
float wordDepth(uint64_t word) {
  return uintBitsToFloat(uint(word >> 32));
}
