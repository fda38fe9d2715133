// The point methods as data: one row per `--method` name. Everything the renderer, the CLI, the
// benchmarks and the documentation know about a method comes from its row, and every list of method
// names (help, errors, `bench --methods all`, the README check) is generated from this table.
//
// Adding a method:
// - a variant of an existing family is one row here plus its shader (or none, when it only sets other
//   specialization constants of an existing shader): the family's code reads the shader name, the
//   specialization constants and the output kind from the row;
// - a new family (a new way of recording a frame) adds a MethodFamily value, its PointMethod class in
//   src/render (method.h) and the factory case in renderer.cpp, then rows as above;
// - a method that reads another kind of GPU input (an octree streamed through a node cache instead of an
//   uploaded scene) adds its value to SceneLayout (render/scene.h) and says so in its rows.
// A test build configured with POINTRAST_TEST_METHODS=ON adds the rows of tests/methods/method_rows.inc
// (shaders in tests/methods): the proof that the above holds, run by scripts/test.sh.
// Code outside src/render asks rows for properties (layout, output, needs), never for a method by name;
// pointMethod("name") names one at compile time where a default or a test needs a particular one.
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gpu/program.h"
#include "render/scene.h"

namespace pointrast {

// Which PointMethod class records the method's frames (one file each in src/render).
enum class MethodFamily {
  Closest,  // method_closest.cpp: one raster shader per point, one resolve; `shader` and `int40Shader`
  BusyLoop, // method_closest.cpp: the per-pixel lock, two uint arrays instead of 64-bit words
  Hqs,      // method_hqs.cpp: closest depth pass, `shader` accumulates, resolve divides
  HwPoints, // method_hw_points.cpp: the graphics point-list pipeline (`shader` is the vertex stage)
  Batch,    // method_batch.cpp: `shader` rasterizes batches; Blend output adds the accumulation pass
  Lod,      // lod/lod_passes.cpp: `shader` rasterizes pages of octree nodes; Blend output adds the
            // accumulation pass. Reads SceneLayout::Octree: Renderer::render(lod::LodScene&, ...)
};

// What the method leaves in the framebuffer, which decides what tests and reports compare.
enum class MethodOutput {
  Closest,   // the canonical closest-point words: bit-identical across the family (docs/design.md,
             // "Equivalence"); the batch rows quantize to 30 bits, same point on >= 99.9 % of pixels
  AnyPoint,  // canonical words of some point of the pixel, not the closest (justset)
  Blend,     // an average of the points near the closest depth (HQS); no canonical words
  ColorOnly, // colors only (the hardware pipeline's attachment); no canonical words
};

// Device features a method needs beyond what every method needs (gpu::Context refuses a device
// without 64-bit buffer atomics and buffer device addresses). --depth int40 adds shaderFloat64.
enum class MethodNeeds : uint32_t {
  None = 0,
  Subgroups = 1u << 0,     // vote, ballot, shuffle and arithmetic in compute shaders
  PartitionedNV = 1u << 1, // VK_NV_shader_subgroup_partitioned
};
constexpr MethodNeeds operator|(MethodNeeds a, MethodNeeds b) {
  return MethodNeeds(uint32_t(a) | uint32_t(b));
}
constexpr bool hasNeed(MethodNeeds set, MethodNeeds need) {
  return (uint32_t(set) & uint32_t(need)) != 0;
}

// The specialization constants of a row, named at the row as at a ComputeProgram call site:
// {{/* EARLY_Z= */ 0, 1}}. A fixed capacity keeps rows constexpr.
class SpecList {
public:
  static constexpr size_t kCapacity = 4;
  constexpr SpecList() = default;
  constexpr SpecList(std::initializer_list<gpu::SpecConstant> list) {
    for (const gpu::SpecConstant& s : list)
      items_[count_++] = s; // a fifth constant does not compile (out of bounds in a constant expression)
  }
  std::span<const gpu::SpecConstant> span() const { return {items_.data(), count_}; }
  // This list followed by `more` (constants the family sets for every row, such as POINTS_PER_THREAD).
  std::vector<gpu::SpecConstant> with(std::initializer_list<gpu::SpecConstant> more) const;

private:
  std::array<gpu::SpecConstant, kCapacity> items_{};
  size_t count_ = 0;
};

struct MethodInfo {
  const char* name; // --method, JSON, reports
  MethodFamily family;
  const char* shader;      // the family's main shader (see MethodFamily), embedded name "x.comp"
  const char* int40Shader; // the same for --depth int40; nullptr: the method has no int40 encoding
  SpecList spec;           // specialization constants of `shader` (and int40Shader)
  MethodNeeds needs;       // device features beyond the common ones
  SceneLayout layout;      // the GPU input it reads
  MethodOutput output;     // what it leaves in the framebuffer
  uint32_t bytesPerPoint;  // point data it must read per point per frame, for the effective bandwidth;
                           // batch rows: the least (one word); FrameStats::batch has what a frame read
  const char* help;        // one line for `render --help` and the README's methods table
};

// bytesPerPoint: 12 B position + 4 B color for the closest-point methods; HQS reads positions in its
// depth pass and positions and colors in its blending pass (28 B); the batch methods 4 to 12 B of
// coordinates (adaptive precision) plus the colors of visible points only, so 4 is the least.
// clang-format off
inline constexpr MethodInfo kPointMethods[] = {
  {"atomicmin", MethodFamily::Closest, "raster_closest.comp", "raster_closest_int40.comp", {},
   MethodNeeds::None, SceneLayout::Float, MethodOutput::Closest, 16,
   "one 64-bit atomicMin of depth<<32|color per point (2019)"},
  {"earlyz", MethodFamily::Closest, "raster_closest.comp", "raster_closest_int40.comp",
   {{/* EARLY_Z= */ 0, 1}},
   MethodNeeds::None, SceneLayout::Float, MethodOutput::Closest, 16,
   "read the pixel first, atomicMin only if closer (2021)"},
  {"reduce", MethodFamily::Closest, "raster_closest.comp", "raster_closest_int40.comp",
   {{/* REDUCE= */ 1, 1}},
   MethodNeeds::Subgroups, SceneLayout::Float, MethodOutput::Closest, 16,
   "subgroup minimum when a subgroup hits one pixel, else pairs (2021)"},
  {"reduce-earlyz", MethodFamily::Closest, "raster_closest.comp", "raster_closest_int40.comp",
   {{/* EARLY_Z= */ 0, 1}, {/* REDUCE= */ 1, 1}},
   MethodNeeds::Subgroups, SceneLayout::Float, MethodOutput::Closest, 16,
   "reduce and early-z (2021)"},
  {"dedup", MethodFamily::Closest, "raster_dedup_nv.comp", "raster_dedup_nv_int40.comp",
   {{/* EARLY_Z= */ 0, 1}},
   MethodNeeds::Subgroups | MethodNeeds::PartitionedNV, SceneLayout::Float, MethodOutput::Closest, 16,
   "one atomic per distinct pixel of a subgroup, VK_NV_shader_subgroup_partitioned, with early-z (2021)"},
  {"dedup-ballot", MethodFamily::Closest, "raster_closest.comp", "raster_closest_int40.comp",
   {{/* EARLY_Z= */ 0, 1}, {/* REDUCE= */ 1, 2}},
   MethodNeeds::Subgroups, SceneLayout::Float, MethodOutput::Closest, 16,
   "dedup from portable subgroup ballots, with early-z"},
  {"busyloop", MethodFamily::BusyLoop, "raster_busyloop.comp", nullptr, {},
   MethodNeeds::None, SceneLayout::Float, MethodOutput::Closest, 16,
   "per-pixel lock in the depth word, then color (2013), with early-z"},
  {"justset", MethodFamily::Closest, "raster_closest.comp", "raster_closest_int40.comp",
   {{/* JUST_SET= */ 2, 1}},
   MethodNeeds::None, SceneLayout::Float, MethodOutput::AnyPoint, 16,
   "plain stores, no depth test: a speed reference, not a correct image"},
  {"hqs", MethodFamily::Hqs, "raster_hqs.comp", nullptr, {{/* ONE_ROUND= */ 0, 0}},
   MethodNeeds::Subgroups, SceneLayout::Float, MethodOutput::Blend, 28,
   "high-quality splatting: blend points within 1% of the closest depth (2019)"},
  {"hqs1r", MethodFamily::Hqs, "raster_hqs.comp", nullptr, {{/* ONE_ROUND= */ 0, 1}},
   MethodNeeds::Subgroups, SceneLayout::Float, MethodOutput::Blend, 28,
   "HQS with one packed 64-bit atomicAdd and overflow fallback (2022)"},
  {"hw-points", MethodFamily::HwPoints, "points_hw.vert", nullptr, {},
   MethodNeeds::None, SceneLayout::Float, MethodOutput::ColorOnly, 16,
   "Vulkan point-list pipeline, 1-pixel points, hardware depth test: the GL_POINTS baseline"},
  {"batch", MethodFamily::Batch, "raster_batch.comp", nullptr, {{/* PREFETCH= */ 0, 0}},
   MethodNeeds::None, SceneLayout::Batched, MethodOutput::Closest, 4,
   "2022: a workgroup per batch of 10240 points, frustum culling, adaptive coordinate precision, "
   "visibility buffer"},
  {"batch-prefetch", MethodFamily::Batch, "raster_batch.comp", nullptr, {{/* PREFETCH= */ 0, 1}},
   MethodNeeds::None, SceneLayout::Batched, MethodOutput::Closest, 4,
   "batch with 128-bit loads, four points in flight per thread (2022)"},
  {"batch-hqs", MethodFamily::Batch, "raster_batch.comp", nullptr,
   {{/* PREFETCH= */ 0, 1}, {/* DEPTH_ONLY= */ 1, 1}},
   MethodNeeds::Subgroups, SceneLayout::Batched, MethodOutput::Blend, 8,
   "HQS on batches: prefetch depth pass, one packed atomicAdd per point with overflow fallback (2022)"},
  {"lod", MethodFamily::Lod, "raster_lod.comp", nullptr, {{/* PREFETCH= */ 0, 1}},
   MethodNeeds::None, SceneLayout::Octree, MethodOutput::Closest, 4,
   "2022 LOD: octree nodes chosen by projected size, streamed into a GPU node cache, drawn as batches"},
  {"lod-hqs", MethodFamily::Lod, "raster_lod.comp", nullptr,
   {{/* PREFETCH= */ 0, 1}, {/* DEPTH_ONLY= */ 1, 1}},
   MethodNeeds::Subgroups, SceneLayout::Octree, MethodOutput::Blend, 8,
   "HQS on octree nodes: depth pass, one packed atomicAdd per point with overflow fallback (2022)"},
#ifdef POINTRAST_TEST_METHOD_ROWS
#include POINTRAST_TEST_METHOD_ROWS // test builds only (CMake POINTRAST_TEST_METHODS)
#endif
};
// clang-format on

// A point method: a row of kPointMethods. Cheap to copy and compare; the default is the first row.
class Method {
public:
  constexpr Method() = default;
  static constexpr Method fromIndex(uint32_t index) { return Method(index); }
  constexpr uint32_t index() const { return index_; }
  constexpr const MethodInfo& info() const { return kPointMethods[index_]; }
  constexpr const char* name() const { return info().name; }
  friend constexpr auto operator<=>(Method, Method) = default;

private:
  constexpr explicit Method(uint32_t index) : index_(index) {}
  uint32_t index_ = 0;
};

// The row named `name`, found at compile time: a misspelt name does not compile.
consteval Method pointMethod(std::string_view name) {
  for (uint32_t i = 0; i < std::size(kPointMethods); ++i)
    if (name == kPointMethods[i].name) return Method::fromIndex(i);
  throw "no point method of this name"; // not a constant expression: a compile error
}

// Every row, in table order.
std::vector<Method> allMethods();
// Throws InputError naming every method.
Method parseMethod(std::string_view name);
inline const MethodInfo& methodInfo(Method method) {
  return method.info();
}
inline const char* methodName(Method method) {
  return method.name();
}
// Whether the method leaves canonical words (depth << 32 | color) in the framebuffer.
inline bool hasCanonicalWords(const MethodInfo& m) {
  return m.output == MethodOutput::Closest || m.output == MethodOutput::AnyPoint;
}
// "a, b and c" of the methods' names.
std::string methodNameList(std::span<const Method> methods);
// The names of the rows that read `layout`, as methodNameList.
std::string methodNamesReading(SceneLayout layout);

} // namespace pointrast
