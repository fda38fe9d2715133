#version 460
// Points larger than one pixel. Rasterizing every point as a shape anchored at its pixel with a 64-bit
// atomicMin gives pixel p the smallest word among points whose shape covers p. A shape's pixels depend
// only on the point's pixel u (and, attenuated, its depth), so that is the smallest word over pixels u
// with p in shape(u) of the points that landed on u; and of those only u's closest point matters: a
// farther point on u has a shape no larger (sizes never grow with depth) and shapes of smaller size lie
// inside larger ones, so whatever it covers the closest one covers with a smaller word. Hence a gather
// over the 1-pixel framebuffer equals the rasterization of shapes exactly (tests/gpu/post_test.cpp checks
// it against a CPU rasterizer), with one difference GL_POINTS shares: a point whose center is outside the
// image draws nothing.
//   SHAPE       kPointShapeSquare or kPointShapeDisc (shared.h gives the pixels of each)
//   ATTENUATED  0: every point has size pc.pointSize; 1: pc.pointSize / depth, clamped to [1, max]
//   AXIS        0: the whole window; fixed squares, whose window is a product of two ranges, are cut into
//               a pass along rows (1) and one along columns (2): 2n words read a pixel instead of n^2
//   SCATTER     1: the same image pushed instead of gathered: each pixel's word goes with atomicMin to the
//               pixels its shape covers (the target filled with kEmptyPixel first). Attenuated sizes use it:
//               a gather reads the largest shape's window at every pixel, a scatter only what the shapes
//               cover, mostly small ones.
#include "post.inc.glsl"

layout(constant_id = 0) const uint SHAPE = kPointShapeSquare;
layout(constant_id = 1) const uint ATTENUATED = 0;
layout(constant_id = 2) const uint AXIS = 0;
layout(constant_id = 3) const uint SCATTER = 0;

float sizeOf(uint64_t word) {
  if (ATTENUATED == 0u) return pc.pointSize;
  return clamp(pc.pointSize / wordDepth(word), 1.0, pc.maxPointSize);
}

// Whether the shape of size s of a point at pixel u covers pixel u + d.
bool covers(float s, ivec2 d) {
  if (SHAPE == kPointShapeDisc) {
    float r = 0.5 * s;
    return float(d.x * d.x + d.y * d.y) <= r * r;
  }
  int n = int(s + 0.5); // side in whole pixels, rounded
  int lo = -((n - 1) >> 1), hi = n >> 1;
  return d.x >= lo && d.x <= hi && d.y >= lo && d.y <= hi;
}

// The smallest word over the pixels p - d, d = (k, 0) (AXIS 1) or (0, k) (AXIS 2), k in a square's range.
uint64_t axisMinimum(ivec2 p) {
  int n = int(pc.pointSize + 0.5);
  uint64_t best = kEmptyPixel;
  for (int k = -((n - 1) >> 1); k <= n >> 1; ++k) {
    ivec2 u = p - (AXIS == 1u ? ivec2(k, 0) : ivec2(0, k));
    if (insideImage(u)) best = min(best, sourceWord(u));
  }
  return best;
}

// Pushes pixel p's word to every pixel its shape covers.
void scatter(ivec2 p) {
  uint64_t w = sourceWord(p);
  if (w == kEmptyPixel) return;
  float s = sizeOf(w);
  int n = int(s + 0.5);
  int lo = SHAPE == kPointShapeDisc ? -int(0.5 * s) : -((n - 1) >> 1);
  int hi = SHAPE == kPointShapeDisc ? int(0.5 * s) : n >> 1;
  Uint64Array target = Uint64Array(pc.target);
  for (int dy = lo; dy <= hi; ++dy) {
    for (int dx = lo; dx <= hi; ++dx) {
      ivec2 q = p + ivec2(dx, dy);
      if (!insideImage(q) || !covers(s, ivec2(dx, dy))) continue;
      uint at = uint(q.y) * pc.targetPitch + uint(q.x);
      if (w < target.v[at]) atomicMin(target.v[at], w); // read first: most covered pixels are taken
    }
  }
}

void main() {
  ivec2 p;
  if (!postPixel(p)) return;
  if (SCATTER != 0u) {
    scatter(p);
    return;
  }
  if (AXIS != 0u) {
    Words(pc.target).v[uint(p.y) * pc.targetPitch + uint(p.x)] = axisMinimum(p);
    return;
  }
  int r = int(pc.radius);
  uint64_t best = kEmptyPixel;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      ivec2 u = p - ivec2(dx, dy); // the point's pixel; p = u + d
      if (!insideImage(u)) continue;
      uint64_t w = sourceWord(u);
      if (w < best && covers(sizeOf(w), ivec2(dx, dy))) best = w; // empty words are never < best
    }
  }
  Words(pc.target).v[uint(p.y) * pc.targetPitch + uint(p.x)] = best;
}
