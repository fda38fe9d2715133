// Fetches point i of the current part (RasterPush pc) and computes its pixel and framebuffer word.
// DEPTH_INT40 (a #define of the entry file, since double precision needs the Float64 capability):
//   0: word = floatBits(c.w) << 32 | RGBA8          (order-preserving: c.w > 0)
//   1: word = uint40(c.w * depthScale) << 24 | RGB24 (the 2019 poster; projection in double precision)
#include "clip.inc.glsl"
#include "project.inc.glsl"

// CLIP (specialization constant 15): the pipeline tests each point against the scene's clip volumes. The
// renderer takes the CLIP = 1 variant only for frames that clip, so that no other frame compiles the test in
// (on lavapipe a test under a false uniform branch still costs its masked instructions).
layout(constant_id = 15) const uint CLIP = 0;

#if DEPTH_INT40
#extension GL_ARB_gpu_shader_fp64 : require
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer DMat4Ref { dmat4 m; };
#endif

// The first point of this thread when each thread draws pointsPerThread points a workgroup size apart
// (first + k * kPointGroupSize, k < pointsPerThread), so that the lanes of a subgroup hold consecutive points.
uint firstPointOfThread(uint pointsPerThread) {
  uint group = gl_WorkGroupID.y * pc.groupsX + gl_WorkGroupID.x;
  return group * (kPointGroupSize * pointsPerThread) + gl_LocalInvocationIndex;
}

vec3 loadPosition(uint i) {
  FloatArray pos = FloatArray(pc.positions);
  return vec3(pos.v[3 * i], pos.v[3 * i + 1], pos.v[3 * i + 2]);
}

// The depth part of point p's framebuffer word (payload 0) and its pixel; false if the point is dropped (by
// the clip volumes too).
bool depthWordOf(vec3 p, out uint pixel, out uint64_t word) {
  pixel = 0xFFFFFFFFu; // written on every path (see projectPoint)
  word = 0xFFFFFFFFFFFFFFFFul;
  if (CLIP != 0u && !sceneKeeps(pc.scene, p)) return false;
#if DEPTH_INT40
  dvec4 c = DMat4Ref((pc.scene & ~kSceneClipped) + kSceneMatrixOffset).m * dvec4(dvec3(p), 1.0lf);
  if (!(c.w > double(pc.nearW))) return false;
  double fx = (c.x / c.w + 1.0lf) * 0.5lf * double(pc.width);
  double fy = (1.0lf - c.y / c.w) * 0.5lf * double(pc.height);
  if (!(fx >= 0.0lf && fx < double(pc.width) && fy >= 0.0lf && fy < double(pc.height))) return false;
  pixel = min(uint(fy), pc.height - 1) * pc.width + min(uint(fx), pc.width - 1);
  double steps = min(c.w * double(pc.depthScale), double(kInt40MaxDepth));
  word = uint64_t(steps) << kInt40ColorBits;
  return true;
#else
  uint depthBits;
  if (!projectPoint(pc.viewProj, p, pc.width, pc.height, pc.nearW, pixel, depthBits)) return false;
  word = uint64_t(depthBits) << 32;
  return true;
#endif
}

// Adds point i's color as the payload of a depth word.
uint64_t withColor(uint64_t word, uint i) {
  uint color = UintArray(pc.colors).v[i];
#if DEPTH_INT40
  return word | uint64_t(color & 0xFFFFFFu);
#else
  return word | uint64_t(color);
#endif
}

// Point i's position, or 0 past the part's end (threads that draw several points load them all first).
vec3 loadPositionOrZero(uint i) {
  return i < pc.pointCount ? loadPosition(i) : vec3(0.0);
}

// withColor = false leaves the payload 0 and skips the color read (depth-only passes read 12 B a point).
bool pointWord(uint i, bool color, out uint pixel, out uint64_t word) {
  if (!depthWordOf(loadPosition(i), pixel, word)) return false;
  if (color) word = withColor(word, i);
  return true;
}
