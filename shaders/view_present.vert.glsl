#version 460
// The viewer's present pass: one triangle that covers the whole target (vertices at (-1,-1), (3,-1),
// (-1,3) in normalized device coordinates), no vertex buffer.
#include "common.inc.glsl"

layout(push_constant) uniform Push { PresentPush pc; };

void main() {
  vec2 corner = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
