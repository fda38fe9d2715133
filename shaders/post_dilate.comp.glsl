#version 460
// Depth-aware dilation (the 2022 paper's hole filling, §3.7). A pixel that is empty, or whose point lies
// more than 1 % behind closer points of its window, is a hole when it lies within the convex hull of
// those closer points (no open half-plane through the pixel holds them all); it then takes the closest of
// them. A hole takes a nearer point only, so a far point never covers a near one; the pixels outside a
// convex silhouette can be separated from it by a line, so objects do not grow; a gap fills where it is at
// most r pixels wide.
#include "post.inc.glsl"

int cross2(ivec2 a, ivec2 b) {
  return a.x * b.y - a.y * b.x;
}

void main() {
  ivec2 p;
  if (!postPixel(p)) return;
  uint64_t own = sourceWord(p);
  // Closer than this counts; an empty pixel's limit is infinite.
  float limit = own == kEmptyPixel ? uintBitsToFloat(0x7F800000u) : wordDepth(own);
  int r = int(pc.radius);
  uint64_t best = kEmptyPixel;
  // The closer points' directions from p span the arc from `lo` counter-clockwise to `hi` (less than half a
  // turn) until `surrounded`: an arc of half a turn or more means no open half-plane holds them.
  ivec2 lo = ivec2(0), hi = ivec2(0);
  bool any = false, surrounded = false;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      ivec2 q = p + ivec2(dx, dy);
      if (!insideImage(q)) continue;
      uint64_t w = sourceWord(q);
      if (w == kEmptyPixel || !(wordDepth(w) * PR_DILATE_DEPTH_FACTOR < limit)) continue;
      best = min(best, w);
      ivec2 d = ivec2(dx, dy);
      if (!any) {
        lo = hi = d;
        any = true;
        continue;
      }
      bool opposite = cross2(lo, d) == 0 && lo.x * d.x + lo.y * d.y < 0;
      if (surrounded || (cross2(lo, d) >= 0 && cross2(d, hi) >= 0 && !opposite)) continue; // in the arc
      // Grow the arc to d on the side that keeps it under half a turn; if neither does, it is surrounded.
      if (cross2(d, hi) > 0) lo = d;
      else if (cross2(lo, d) > 0) hi = d;
      else surrounded = true;
    }
  }
  Words(pc.target).v[uint(p.y) * pc.targetPitch + uint(p.x)] = surrounded ? best : own;
}
