#version 460
// Depth-aware dilation (the 2022 paper's hole filling, §3.7): a pixel that is empty, or whose point lies
// more than 1 % behind closer points around it, is a hole when those closer points lie on both sides of
// it (left and right, or above and below) within the window; it then takes the closest of them. A hole
// is filled with a nearer point only, so a far point never covers a near one; and the pixels just outside
// an object's silhouette have closer points on one side only, so objects do not grow.
#include "post.inc.glsl"

void main() {
  ivec2 p;
  if (!postPixel(p)) return;
  uint64_t own = sourceWord(p);
  // Closer than this counts; an empty pixel's limit is infinite (its word's depth bits are NaN).
  float limit = own == kEmptyPixel ? uintBitsToFloat(0x7F800000u) : wordDepth(own);
  int r = int(pc.radius);
  uint64_t best = kEmptyPixel;
  bool left = false, right = false, above = false, below = false;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      ivec2 q = p + ivec2(dx, dy);
      if (!insideImage(q)) continue;
      uint64_t w = sourceWord(q);
      if (w == kEmptyPixel || !(wordDepth(w) * PR_DILATE_DEPTH_FACTOR < limit)) continue;
      best = min(best, w);
      left = left || dx < 0;
      right = right || dx > 0;
      above = above || dy < 0;
      below = below || dy > 0;
    }
  }
  bool hole = (left && right) || (above && below);
  Words(pc.target).v[uint(p.y) * pc.targetPitch + uint(p.x)] = hole ? best : own;
}
