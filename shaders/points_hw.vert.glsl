#version 460
// hw-points: the hardware point primitive (GL_POINTS in the papers, a Vulkan point list here), one vertex
// per point, 1-pixel points, the fixed-function depth test. The baseline the compute methods are measured
// against, so it is the plain pipeline a viewer would use: no culling, no tricks.
//
// Image contract (docs/design.md) through the fixed-function stages:
//   x, y   Vulkan's viewport maps NDC x = -1 to the left edge and NDC y = -1 to the top row, so
//          (c.x, -c.y, ., c.w) puts the point at fx = (c.x/c.w + 1)/2 W, fy = (1 - c.y/c.w)/2 H, and a
//          1-pixel point square covers the pixel (floor(fx), floor(fy)) up to subpixel snapping at borders.
//   depth  reverse-Z with an infinite far plane: z = nearW, so depth = z/w = nearW / c.w. It falls strictly
//          with the linear depth c.w, lies in (0, 1) for c.w > nearW, and keeps float's relative precision
//          at every distance (a standard 1 - near/w depth loses it all far from the eye: 1e5 near-planes
//          away, points 0.6 % apart in depth would tie in D32_SFLOAT). The pipeline tests GREATER against
//          a clear of 0, so the point with the smallest c.w wins.
//   near   points with c.w <= nearW are moved outside the clip volume; Vulkan discards a point whose vertex
//          is outside it, as it does for points left or right of the image.
#include "common.inc.glsl"
#include "clip.inc.glsl"

layout(push_constant) uniform Push { RasterPush pc; };
layout(location = 0) flat out uint color;

void main() {
  uint i = gl_VertexIndex;
  FloatArray pos = FloatArray(pc.positions);
  vec3 p = vec3(pos.v[3 * i], pos.v[3 * i + 1], pos.v[3 * i + 2]);
  vec4 c = pc.viewProj * vec4(p, 1.0);
  color = UintArray(pc.colors).v[i];
  gl_PointSize = 1.0;
  // !(>) also drops NaN depths; a point the clip volumes drop goes outside the clip volume like one behind.
  bool kept = c.w > pc.nearW && sceneKeeps(pc.scene, p);
  gl_Position = kept ? vec4(c.x, -c.y, pc.nearW, c.w) : vec4(2.0, 2.0, 2.0, 1.0);
}
