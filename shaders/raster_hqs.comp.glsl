#version 460
// High-quality splatting, accumulation pass (2019 paper; hqs1r: the single-atomic form of the 2022 paper).
// The depth pass left the closest linear depth in the high word of the framebuffer; here every point whose
// linear depth is within 1 % of it adds its color to the pixel (hqs_accumulate.inc.glsl).
//   ONE_ROUND 0 (hqs):   aux = 2 uint64 per pixel: (r << 32 | g), (b << 32 | count); two atomicAdds
//   ONE_ROUND 1 (hqs1r): aux = 1 uint64 per pixel packing r, g, b, count in 16 bits each, one atomicAdd;
//                        then 2 uint64 per pixel of 32-bit fallback sums for points past the 255th.
// A thread draws 4 consecutive points (three 16-byte position loads; the colors, one 16-byte load, only if one
// of them blends): it adds them per pixel before the subgroup does (hqsMergeFour), so a subgroup step covers
// 128 consecutive points and makes a few atomics for them. That, not the loads, decides the pass's speed in
// dense views (docs/performance.md, "HQS: what the accumulation pass spends").
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_EXT_control_flow_attributes : require
#include "common.inc.glsl"
#include "hqs_accumulate.inc.glsl"

layout(local_size_x = kPointGroupSize) in;
layout(push_constant) uniform Push { RasterPush pc; };
layout(constant_id = 0) const uint ONE_ROUND = 0;
#define DEPTH_INT40 0
#include "point.inc.glsl"

// Points are 12 B (x, y, z) and a part's buffers start 16-byte aligned, so 4 points from a multiple of 4 are
// three aligned vec4s; the part's last, partial quad is read point by point.
void loadFour(uint first, out vec3 p[4]) {
  if (first + 3u < pc.pointCount) {
    Vec4Array a = Vec4Array(pc.positions);
    uint at = 3u * (first / 4u);
    vec4 q0 = a.v[at], q1 = a.v[at + 1u], q2 = a.v[at + 2u];
    p[0] = q0.xyz;
    p[1] = vec3(q0.w, q1.xy);
    p[2] = vec3(q1.zw, q2.x);
    p[3] = q2.yzw;
  } else {
    [[unroll]] for (uint k = 0u; k < 4u; ++k) p[k] = loadPositionOrZero(first + k);
  }
}

uvec4 loadColors(uint first) {
  if (first + 3u < pc.pointCount) return Uvec4Array(pc.colors).v[first / 4u];
  uvec4 c = uvec4(0u);
  [[unroll]] for (uint k = 0u; k < 4u; ++k)
    if (first + k < pc.pointCount) c[k] = UintArray(pc.colors).v[first + k];
  return c;
}

void main() {
  // No early return anywhere: the subgroup operations of hqsBlend need every lane.
  const uint chunkPoints = kPointGroupSize * 4u;
  uint chunk = hqsInterleavedChunk(gl_WorkGroupID.y * pc.groupsX + gl_WorkGroupID.x,
                                   (pc.pointCount + chunkPoints - 1u) / chunkPoints);
  uint first = chunk * chunkPoints + 4u * gl_LocalInvocationIndex;
  vec3 p[4];
  loadFour(first, p);
  // Project all four, then read their pixels' closest depths together, then the colors if any blends.
  uint pixel[4];
  float depth[4];
  [[unroll]] for (uint k = 0u; k < 4u; ++k) {
    uint64_t word;
    depth[k] = 0.0;
    if (first + k < pc.pointCount && depthWordOf(p[k], pixel[k], word))
      depth[k] = uintBitsToFloat(uint(word >> 32));
    else
      pixel[k] = kNoPixel;
  }
  Uint64Array fb = Uint64Array(pc.framebuffer);
  bool blends = false;
  [[unroll]] for (uint k = 0u; k < 4u; ++k) {
    if (pixel[k] == kNoPixel) continue;
    float closest = uintBitsToFloat(uint(fb.v[pixel[k]] >> 32));
    if (depth[k] > closest * float(PR_HQS_DEPTH_FACTOR)) pixel[k] = kNoPixel; // hidden: not blended
    blends = blends || pixel[k] != kNoPixel;
  }
  uvec4 colors = blends ? loadColors(first) : uvec4(0u); // hidden points cost their 12 B of position alone
  uint r[4], g[4], b[4], n[4];
  [[unroll]] for (uint k = 0u; k < 4u; ++k) {
    bool blended = pixel[k] != kNoPixel;
    hqsChannels(blended ? colors[k] : 0u, r[k], g[k], b[k]);
    n[k] = blended ? 1u : 0u;
  }
  hqsMergeFour(pixel, r, g, b, n);
  [[unroll]] for (uint k = 0u; k < 4u; ++k)
    hqsBlend(Uint64Array(pc.aux), pc.width * pc.height, ONE_ROUND != 0, pixel[k], r[k], g[k], b[k], n[k]);
}
