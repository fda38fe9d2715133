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

// Push constants of the point rasterizers: one dispatch draws one part of a scene (a range of points
// living in one buffer pair), addressed by buffer device address so parts may be anywhere in memory and
// scenes may exceed the 4 GiB range of a storage-buffer descriptor. 128 bytes: the minimum every Vulkan
// device must allow.
struct RasterPush {
  mat4 viewProj;         // world-relative-to-origin -> clip; only rows x, y, w are used
  uint64_t positions;    // address of float[3 * pointCount]
  uint64_t colors;       // address of uint[pointCount] (RGBA8)
  uint64_t framebuffer;  // address of the method's framebuffer (uint64_t per pixel for most methods)
  uint64_t aux;          // method-specific buffer (HQS accumulators), 0 if none
  uint64_t viewProjD;    // address of a dmat4: the same matrix in double precision (int40 depth)
  uint pointCount;
  uint width;
  uint height;
  float nearW;           // points with c.w <= nearW are dropped
  uint groupsX;          // workgroups per row of a 2D dispatch (a 1D grid may not exceed 65535 groups)
  float depthScale;      // int40 depth: integer steps per unit of linear depth (1000: millimetres)
};

// Push constants of the resolve passes (framebuffer -> RGBA8 image, and optionally canonical words).
struct ResolvePush {
  uint64_t framebuffer; // the method's framebuffer
  uint64_t image;       // uint[width * height], RGBA8, row 0 = top
  uint64_t aux;         // method-specific (HQS accumulators)
  uint64_t words;       // if not 0: uint64_t[width * height] receives depth << 32 | color per pixel
  uint width;
  uint height;
  uint background;      // RGBA8 written where no point landed
  uint groupsX;         // workgroups per row of the 2D dispatch
};

// Push constants of the shader copy that measures the device's copy bandwidth (src/gpu/bandwidth.cpp).
struct CopyPush {
  uint64_t source;      // uvec4[count]
  uint64_t destination; // uvec4[count]
  uint count;           // 16-byte elements
  uint groupsX;
};

// Word layout of the int40 depth encoding (the 2019 poster): 40-bit integer depth << 24 | 24-bit RGB.
PR_CONST kInt40ColorBits = 24;
PR_CONST64 kInt40MaxDepth = 0xFFFFFFFFFFul; // 2^40 - 1 steps: 1,099 km at 1 mm per step

// Busy-loop method: the framebuffer is two uint arrays (depth bits, then color); the top bit of a depth
// word is the pixel's lock (linear depth is a positive float, so its sign bit is free).
PR_CONST kPixelLockBit = 0x80000000u;
PR_CONST kEmptyDepthBits = 0x7FFFFFFFu; // above every finite positive float

// High-quality splatting (2019): a point is blended into its pixel if its linear depth is within 1 % of
// the closest point's.
#define PR_HQS_DEPTH_FACTOR 1.01
// hqs1r: one 64-bit word per pixel packs r, g, b, count in 16 bits each. 255 points of 255 sum to 65025,
// below 2^16, so a pixel stays exact up to 255 points; later points go to 32-bit fallback sums.
PR_CONST kHqs1rMaxCount = 255;

PR_NAMESPACE_END

#endif
