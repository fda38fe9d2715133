#version 460
// The last pass of the resolve stage: background where no point landed, eye-dome lighting when
// pc.edlStrength > 0 (shared.h gives Potree's formula), the RGBA8 image, and the final words on request.
#include "post.inc.glsl"

// Unit directions k * 45 degrees, k = 0..7.
const vec2 kDirections[kEdlNeighbours] =
    vec2[](vec2(1.0, 0.0), vec2(0.70710678, 0.70710678), vec2(0.0, 1.0), vec2(-0.70710678, 0.70710678),
           vec2(-1.0, 0.0), vec2(-0.70710678, -0.70710678), vec2(0.0, -1.0), vec2(0.70710678, -0.70710678));

// Eye-dome lighting's shade of a pixel holding a point at linear depth `depth`.
float edlShade(ivec2 p, float depth) {
  float logDepth = log2(depth);
  float sum = 0.0;
  for (uint k = 0u; k < kEdlNeighbours; ++k) {
    // The neighbour is the pixel under the pixel center moved by radius in direction k (nearest pixel),
    // clamped to the image as a texture lookup clamps to its edge.
    ivec2 q = ivec2(floor(vec2(p) + 0.5 + pc.edlRadius * kDirections[k]));
    q = clamp(q, ivec2(0), ivec2(pc.width - 1u, pc.height - 1u));
    uint64_t w = sourceWord(q);
    if (w != kEmptyPixel) sum += max(0.0, logDepth - log2(wordDepth(w)));
  }
  float response = sum / float(kEdlNeighbours);
  return exp(-response * float(PR_EDL_EXPONENT) * pc.edlStrength);
}

void main() {
  ivec2 p;
  if (!postPixel(p)) return;
  uint64_t word = sourceWord(p);
  uint color = pc.background;
  if (word != kEmptyPixel) {
    color = uint(word);
    if (pc.edlStrength > 0.0) {
      vec3 rgb = unpackUnorm4x8(color).rgb * edlShade(p, wordDepth(word));
      color = packUnorm4x8(vec4(rgb, 1.0)); // rounds to nearest, as a UNORM attachment does
    }
  }
  uint at = uint(p.y) * pc.targetPitch + uint(p.x);
  UintArray(pc.target).v[at] = color;
  if (pc.words != 0ul) Uint64Array(pc.words).v[at] = word;
}
