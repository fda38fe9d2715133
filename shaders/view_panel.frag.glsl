#version 460
// The panel's fragments: vertex color times the font atlas' coverage, bilinearly filtered by hand (the
// atlas is a buffer, not an image: no sampler, no descriptor set). Blending is SRC_ALPHA, 1 - SRC_ALPHA.
// An image draw (pc.image = 1, ImGui::Image) reads an RGBA8 buffer instead, nearest texel, so that a
// picture shown at its own size keeps its pixels.
#include "common.inc.glsl"

layout(push_constant) uniform Push { PanelPush pc; };
layout(location = 0) in vec2 uv;
layout(location = 1) in vec4 color;
layout(location = 0) out vec4 outColor;

float texel(ivec2 p) {
  p = clamp(p, ivec2(0), ivec2(pc.fontWidth - 1, pc.fontHeight - 1));
  uint i = uint(p.y) * pc.fontWidth + uint(p.x);
  return float((UintArray(pc.font).v[i >> 2] >> ((i & 3) * 8)) & 0xFFu) / 255.0;
}

void main() {
  if (pc.image != 0u) {
    ivec2 q = clamp(ivec2(floor(uv * vec2(pc.fontWidth, pc.fontHeight))), ivec2(0),
                    ivec2(pc.fontWidth - 1, pc.fontHeight - 1));
    outColor = color * unpackUnorm4x8(UintArray(pc.font).v[uint(q.y) * pc.fontWidth + uint(q.x)]);
    return;
  }
  vec2 p = uv * vec2(pc.fontWidth, pc.fontHeight) - 0.5;
  ivec2 p0 = ivec2(floor(p));
  vec2 f = p - vec2(p0);
  float coverage = mix(mix(texel(p0), texel(p0 + ivec2(1, 0)), f.x),
                       mix(texel(p0 + ivec2(0, 1)), texel(p0 + ivec2(1, 1)), f.x), f.y);
  outColor = vec4(color.rgb, color.a * coverage);
}
