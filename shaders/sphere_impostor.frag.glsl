#version 460
// The fragment stage of every rasterization sphere pipeline: ray-casts the sphere through the pixel
// center with the shared intersection and shading (sphere_shade.inc.glsl), discards a miss, and writes
// the shaded color, the particle index and the hit's depth.
//
// Depth is reverse-Z as in hw-points: nearW / (view depth of the hit), falling with the view depth,
// compared GREATER against a clear of 0. The impostor is rasterized at the depth of the sphere's front,
// nearW / (center depth - radius), and no hit is nearer than the front, so the written depth is never
// greater than the rasterized one: depth_less (conservative depth) lets the GPU keep its early depth
// test although the shader writes gl_FragDepth. (With a standard depth buffer this would be
// depth_greater.)
#include "common.inc.glsl"
#include "sphere_shade.inc.glsl"

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SphereFrameRef {
  SphereFrame f;
};
layout(push_constant) uniform Push { SpherePush pc; };
layout(location = 0) flat in vec4 centerRadius;
layout(location = 1) flat in vec4 color;
layout(location = 2) flat in uint index;
layout(location = 0) out vec4 outColor;
layout(location = 1) out uint outIndex;
layout(depth_less) out float gl_FragDepth;

void main() {
  SphereFrameRef frame = SphereFrameRef(pc.frame);
  vec3 dir = sphereRay(frame.f.pixelToRay, gl_FragCoord.xy);
  float depth;
  if (!intersectSphere(centerRadius.xyz, centerRadius.w, dir, depth)) discard;
  outColor = shadeSphere(centerRadius.xyz, dir, depth, color);
  outIndex = index;
  gl_FragDepth = frame.f.nearW / depth;
}
