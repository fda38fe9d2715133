// Draws GPU scenes with one of the methods of the four papers and resolves to an RGBA8 image. All
// closest-point methods write the same framebuffer words for the same input and camera (DESIGN.md,
// "Equivalence"); they differ only in how they get there, which is what the benchmarks compare.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "render/camera.h"
#include "render/scene.h"

namespace pointrast {

namespace gpu {
class Context;
}

enum class Method {
  AtomicMin,    // 2019: one 64-bit atomicMin of (depth << 32 | color) per point
  EarlyZ,       // 2021: read first, atomicMin only if closer
  Reduce,       // 2021: subgroup reduction before the atomic
  ReduceEarlyZ, // 2021: both
  Dedup,        // 2021: one atomic per distinct pixel of the subgroup (VK_NV_shader_subgroup_partitioned)
  DedupBallot,  // dedup built from portable subgroup ballots
  BusyLoop,     // 2013 per-pixel lock, with early-z
  JustSet,      // plain stores without depth test: a speed reference only
  Hqs,          // 2019 high-quality splatting: depth pass + two-atomic accumulation + resolve
  Hqs1r,        // 2022 single-atomic HQS (16-bit packed) with overflow fallback
  HwPoints,     // the hardware point list (GL_POINTS): graphics pipeline, 1-pixel points, depth test
};

enum class DepthMode {
  Float, // IEEE bits of the linear depth, 32 bits, color in the low 32 bits
  Int40, // 2019 poster: depth in double precision, 40-bit integer steps, color in the low 24 bits
};

struct MethodInfo {
  Method method;
  const char* name;
  const char* description;
  bool closest;           // writes the canonical closest-point framebuffer (bit-identical across methods)
  bool int40;             // supports --depth int40
  uint32_t bytesPerPoint; // point data the method must read per point per frame (for effective bandwidth)
};
std::span<const MethodInfo> methodTable();
const MethodInfo& methodInfo(Method method);
// Throws InputError listing the known names.
Method parseMethod(std::string_view name);
const char* methodName(Method method);
DepthMode parseDepthMode(std::string_view name);
const char* depthModeName(DepthMode mode);

struct RenderSettings {
  Method method = Method::AtomicMin;
  DepthMode depth = DepthMode::Float;
  // int40: integer steps per unit of linear depth. 0 (default): the 40 bits span [0, distance from the
  // eye to the farthest corner of the scene bounds], e.g. 9 nm per step for a scene 10 km deep.
  double depthScale = 0.0;
  uint32_t background = 0xFF000000u; // RGBA8, opaque black
  uint32_t frames = 1;               // timed frames; the median is reported
  uint32_t warmup = 1;               // untimed frames first (pipeline caches, clocks)
  bool captureWords = false;         // keep canonical words of the last frame for framebufferWords()
};

struct FrameStats {
  double medianMs = 0, minMs = 0, maxMs = 0; // GPU time of clear + draw + resolve, timestamp queries
  uint32_t frames = 0;
  uint64_t points = 0; // points submitted per frame
};

struct Targets;
class PointMethod;

class Renderer {
public:
  // Throws InputError for a zero or oversized image.
  Renderer(gpu::Context& context, uint32_t width, uint32_t height);
  ~Renderer();

  // Throws UnsupportedError if the device cannot run the method (missing extension or feature) and
  // InputError for a combination that does not exist (hqs with int40 depth).
  FrameStats render(std::span<const GpuScene* const> scenes, const Camera& camera,
                    const RenderSettings& settings);
  FrameStats render(const GpuScene& scene, const Camera& camera, const RenderSettings& settings) {
    const GpuScene* one[] = {&scene};
    return render(one, camera, settings);
  }

  // RGBA8 pixels of the last frame, row 0 at the top.
  std::vector<uint32_t> image();
  // Canonical words (depth << 32 | color, all ones where empty) of the last frame rendered with
  // captureWords; for closest-point methods only.
  std::vector<uint64_t> framebufferWords();

  uint32_t width() const;
  uint32_t height() const;

  // Whether the device can run a method (and why not, in one sentence, when it cannot).
  static bool supports(gpu::Context& context, Method method, std::string* why = nullptr);

private:
  PointMethod& method(const RenderSettings& settings);
  gpu::Context& context_;
  std::unique_ptr<Targets> targets_;
  std::map<std::pair<Method, DepthMode>, std::unique_ptr<PointMethod>> methods_;
  bool wordsCaptured_ = false; // the last frame wrote canonical words
};

} // namespace pointrast
