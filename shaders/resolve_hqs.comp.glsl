#version 460
// HQS resolve: average color = rounded sum / count, from the two-atomic sums (ONE_ROUND 0) or from the
// packed 16-bit sums plus the 32-bit fallback sums (ONE_ROUND 1). Both give the same integers. Words, on
// request, pair the closest depth of the depth pass (pc.framebuffer) with the average.
#include "common.inc.glsl"
#include "grid.inc.glsl"

layout(local_size_x = kPixelGroupSize) in;
layout(push_constant) uniform Push { ResolvePush pc; };
layout(constant_id = 0) const uint ONE_ROUND = 0;

void main() {
  uint i = linearInvocation(pc.groupsX, kPixelGroupSize);
  uint pixels = pc.width * pc.height;
  if (i >= pixels) return;
  Uint64Array acc = Uint64Array(pc.aux);
  uint64_t r, g, b, n;
  uint64_t fallbackRG = acc.v[(ONE_ROUND == 0 ? 0 : pixels) + 2 * i];
  uint64_t fallbackBN = acc.v[(ONE_ROUND == 0 ? 0 : pixels) + 2 * i + 1];
  r = fallbackRG >> 32;
  g = fallbackRG & 0xFFFFFFFFul;
  b = fallbackBN >> 32;
  n = fallbackBN & 0xFFFFFFFFul;
  if (ONE_ROUND != 0) {
    uint64_t packed = acc.v[i];
    r += packed & 0xFFFFul;
    g += (packed >> 16) & 0xFFFFul;
    b += (packed >> 32) & 0xFFFFul;
    n += packed >> 48;
  }
  uint color = pc.background;
  if (n > 0ul) {
    uint64_t half_ = n / 2ul;
    color = uint((r + half_) / n) | (uint((g + half_) / n) << 8) | (uint((b + half_) / n) << 16) | 0xFF000000u;
  }
  UintArray(pc.image).v[i] = color;
  if (pc.words != 0ul) {
    uint64_t depth = Uint64Array(pc.framebuffer).v[i] & 0xFFFFFFFF00000000ul;
    Uint64Array(pc.words).v[i] = n > 0ul ? depth | uint64_t(color) : kEmptyPixel;
  }
}
