#version 460
// High-quality splatting, accumulation pass (2019 paper, and the single-atomic form of the 2022 paper).
// The depth pass (raster_closest with early-z) left the closest point's word in the framebuffer; here
// every point whose linear depth is within 1 % of it adds its color to the pixel.
//   ONE_ROUND 0 (hqs):   aux = 2 uint64 per pixel: (r << 32 | g), (b << 32 | count); two atomicAdds
//   ONE_ROUND 1 (hqs1r): aux = 1 uint64 per pixel packing r, g, b, count in 16 bits each, one atomicAdd;
//                        then 2 uint64 per pixel of 32-bit fallback sums for points past the 255th.
#include "common.inc.glsl"

layout(local_size_x = kPointGroupSize) in;
layout(push_constant) uniform Push { RasterPush pc; };
layout(constant_id = 0) const uint ONE_ROUND = 0;
#define DEPTH_INT40 0
#include "point.inc.glsl"

void main() {
  uint i = linearInvocation(pc.groupsX, kPointGroupSize);
  if (i >= pc.pointCount) return;
  uint pixel;
  uint64_t word;
  if (!pointWord(i, pixel, word)) return;
  float closest = uintBitsToFloat(uint(Uint64Array(pc.framebuffer).v[pixel] >> 32));
  float depth = uintBitsToFloat(uint(word >> 32));
  if (depth > closest * float(PR_HQS_DEPTH_FACTOR)) return;
  uint64_t r = uint64_t(word & 0xFFul), g = uint64_t((word >> 8) & 0xFFul), b = uint64_t((word >> 16) & 0xFFul);
  Uint64Array acc = Uint64Array(pc.aux);
  uint pixels = pc.width * pc.height;
  if (ONE_ROUND == 0) {
    atomicAdd(acc.v[2 * pixel], (r << 32) | g);
    atomicAdd(acc.v[2 * pixel + 1], (b << 32) | 1ul);
    return;
  }
  uint64_t packed = r | (g << 16) | (b << 32) | (1ul << 48);
  uint64_t before = atomicAdd(acc.v[pixel], packed);
  if (uint(before >> 48) < kHqs1rMaxCount) return;
  // The word already held 255 points: this add may have carried across fields. Take it back (modular
  // addition undoes exactly, whatever carries happened) and add to the 32-bit fallback sums instead.
  // Every add that stays saw fewer than 255 stayed adds before it, so at most 255 stay: no overflow.
  atomicAdd(acc.v[pixel], -packed);
  atomicAdd(acc.v[pixels + 2 * pixel], (r << 32) | g);
  atomicAdd(acc.v[pixels + 2 * pixel + 1], (b << 32) | 1ul);
}
