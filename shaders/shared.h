// The one definition of every struct and constant shared by C++ and GLSL. C++ includes it through
// gpu/shared_types.h, which static_asserts sizes and offsets; shaders include it directly.
//
// Push-constant blocks use std430 rules (GLSL's default for push constants): 8-byte members sit at
// multiples of 8, a mat4 is 64 bytes; the C++ side mirrors the order so no hand padding is needed.
#ifndef POINTRAST_SHARED_H
#define POINTRAST_SHARED_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
#define PR_NAMESPACE_BEGIN namespace pointrast::shared {
#define PR_NAMESPACE_END }
#define PR_CONST constexpr uint32_t
#define PR_CONST64 constexpr uint64_t
PR_NAMESPACE_BEGIN
using uint = uint32_t;
using mat4 = glm::mat4;
using vec4 = glm::vec4;
using uvec2 = glm::uvec2;
PR_NAMESPACE_END
#else
#define PR_NAMESPACE_BEGIN
#define PR_NAMESPACE_END
#define PR_CONST const uint
#define PR_CONST64 const uint64_t
#endif

PR_NAMESPACE_BEGIN

// Threads per workgroup of the point kernels: 128 = 4 NVIDIA warps or 2 AMD wave64s; the 2022 batch
// layout (128 threads x 80 points) keeps the same width.
PR_CONST kPointGroupSize = 128;
// Threads per workgroup of per-pixel passes (resolve/clear): 256, a multiple of every subgroup size.
PR_CONST kPixelGroupSize = 256;

// Framebuffer word of the closest-point methods: depth in the high 32 bits (IEEE bits of the linear view
// depth c.w, which is > 0 and so orders like an unsigned integer), payload in the low 32 bits (RGBA8).
// An empty pixel holds all ones, which no point's word can reach (NaN depth bits are never written).
PR_CONST64 kEmptyPixel = 0xFFFFFFFFFFFFFFFFul;

// Push constants of the point rasterizer: one dispatch draws one part of a scene (a range of points
// living in one buffer pair), addressed by buffer device address so parts may be anywhere in memory and
// scenes may exceed the 4 GiB range of a storage-buffer descriptor.
struct RasterPush {
  mat4 viewProj;        // world-relative-to-origin -> clip; only rows x, y, w are used
  uint64_t positions;   // address of float[3 * pointCount]
  uint64_t colors;      // address of uint[pointCount] (RGBA8)
  uint64_t framebuffer; // address of uint64_t[width * height]
  uint pointCount;
  uint width;
  uint height;
  float nearW;          // points with c.w <= nearW are dropped
  uint groupsX;         // workgroups per row of a 2D dispatch (a 1D grid may not exceed 65535 groups)
  uint pad0;
};

// Push constants of the resolve pass (framebuffer words -> RGBA8 image).
struct ResolvePush {
  uint64_t framebuffer; // uint64_t[width * height]
  uint64_t image;       // uint[width * height], RGBA8, row 0 = top
  uint width;
  uint height;
  uint background;      // RGBA8 written where no point landed
  uint groupsX;         // workgroups per row of the 2D dispatch
};

PR_NAMESPACE_END

#endif
