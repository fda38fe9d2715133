#version 460
// sphere-geom: expands each sphere's point into a 4-vertex strip over its projected bounds (passed in
// gl_Position by sphere_geom.vert.glsl), at the depth of its front; a culled sphere emits nothing.
#include "common.inc.glsl"

layout(points) in;
layout(triangle_strip, max_vertices = 4) out;
layout(push_constant) uniform Push { SpherePush pc; };
layout(location = 0) flat in vec4 inCenterRadius[];
layout(location = 1) flat in vec4 inColor[];
layout(location = 2) flat in uint inIndex[];
layout(location = 3) flat in float inDepth[];
layout(location = 0) flat out vec4 centerRadius;
layout(location = 1) flat out vec4 color;
layout(location = 2) flat out uint index;

void main() {
  if (inIndex[0] == kNoParticle) return;
  vec4 ndc = gl_in[0].gl_Position;
  for (uint corner = 0; corner < 4; ++corner) {
    centerRadius = inCenterRadius[0];
    color = inColor[0];
    index = inIndex[0];
    gl_Position =
        vec4((corner & 1u) != 0u ? ndc.z : ndc.x, (corner & 2u) != 0u ? ndc.w : ndc.y, inDepth[0], 1.0);
    EmitVertex();
  }
  EndPrimitive();
}
