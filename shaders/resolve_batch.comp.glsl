#version 460
// Visibility buffer -> RGBA8 image (2022): the color of each pixel's closest point, fetched from its part's
// colors through the frame's table (ResolvePush::aux = BatchFrame), so colors are read for visible points
// only. Optionally the canonical words (depth << 32 | color) that equivalence tests compare.
#include "common.inc.glsl"
#include "grid.inc.glsl"

layout(local_size_x = kPixelGroupSize) in;
layout(push_constant) uniform Push { ResolvePush pc; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer FrameRef { BatchFrame f; };

void main() {
  uint i = linearInvocation(pc.groupsX, kPixelGroupSize);
  if (i >= pc.width * pc.height) return;
  uint64_t word = Uint64Array(pc.framebuffer).v[i];
  bool empty = word == kEmptyPixel;
  uint color = pc.background;
  if (!empty) {
    uint index = uint(word);
    uint64_t colors = FrameRef(pc.aux).f.partColors[index >> kVisibilityPartShift];
    color = UintArray(colors).v[index & kVisibilityLocalMask];
  }
  UintArray(pc.image).v[i] = color;
  if (pc.words != 0ul)
    Uint64Array(pc.words).v[i] = empty ? kEmptyPixel : (word & 0xFFFFFFFF00000000ul) | uint64_t(color);
}
