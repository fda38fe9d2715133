#version 460
// The viewer's panel: Dear ImGui's triangles, pulled by device address (no vertex input state). Index i of
// a draw is indices[firstIndex + i] + vertexOffset; 16-bit indices are read two to a uint.
#include "common.inc.glsl"

layout(push_constant) uniform Push { PanelPush pc; };
layout(location = 0) out vec2 uv;
layout(location = 1) out vec4 color;

void main() {
  uint at = pc.firstIndex + gl_VertexIndex;
  uint pair = UintArray(pc.indices).v[at >> 1];
  uint index = ((at & 1) != 0 ? pair >> 16 : pair & 0xFFFFu) + pc.vertexOffset;
  UintArray v = UintArray(pc.vertices);
  uint base = index * 5; // ImDrawVert: 5 uints
  vec2 position = vec2(uintBitsToFloat(v.v[base]), uintBitsToFloat(v.v[base + 1]));
  uv = vec2(uintBitsToFloat(v.v[base + 2]), uintBitsToFloat(v.v[base + 3]));
  color = unpackUnorm4x8(v.v[base + 4]);
  gl_Position = vec4(position * vec2(pc.scaleX, pc.scaleY) - 1.0, 0.0, 1.0);
}
