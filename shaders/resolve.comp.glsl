#version 460
// Framebuffer -> RGBA8 image (background where no point landed), and optionally the canonical words
// (depth << 32 | color) that equivalence tests compare across methods.
//   LAYOUT 0: uint64 words, float depth << 32 | RGBA8 (atomicMin family)
//   LAYOUT 1: uint64 words, int40 depth << 24 | RGB24 (alpha restored as 255); words in float depth for
//             the resolve stage when pc.int40Scale > 0
//   LAYOUT 2: busy-loop arrays: uint depth[pixels], then uint color[pixels]
#include "common.inc.glsl"
#include "grid.inc.glsl"

layout(local_size_x = kPixelGroupSize) in;
layout(push_constant) uniform Push { ResolvePush pc; };
layout(constant_id = 0) const uint LAYOUT = 0;

void main() {
  uint i = linearInvocation(pc.groupsX, kPixelGroupSize);
  uint pixels = pc.width * pc.height;
  if (i >= pixels) return;
  uint64_t word;
  bool empty;
  uint color;
  if (LAYOUT == 2) {
    UintArray arrays = UintArray(pc.framebuffer);
    uint depth = arrays.v[i];
    color = arrays.v[pixels + i];
    empty = depth == kEmptyDepthBits;
    word = empty ? kEmptyPixel : (uint64_t(depth) << 32) | uint64_t(color);
  } else {
    word = Uint64Array(pc.framebuffer).v[i];
    empty = word == kEmptyPixel;
    color = LAYOUT == 1 ? (uint(word) & 0xFFFFFFu) | 0xFF000000u : uint(word);
  }
  UintArray(pc.image).v[i] = empty ? pc.background : color;
  if (LAYOUT == 1 && pc.int40Scale > 0.0 && !empty)
    word = uint64_t(floatBitsToUint(float(word >> kInt40ColorBits) / pc.int40Scale)) << 32 | uint64_t(color);
  if (pc.words != 0ul) Uint64Array(pc.words).v[i] = word;
}
