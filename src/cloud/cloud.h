// The host model of a point cloud. Positions keep the precision of their source as int32 + per-axis
// scale and offset (as LAS stores them): world = double(q) * scale + offset. Everything that becomes
// float32 for the GPU is first made relative to origin() in double precision, so UTM or ECEF
// coordinates do not lose their low digits.
//
// Attributes are parallel arrays; an empty array means the source has no such attribute.
// Memory per point: 12 B positions + 4 B color (+ 2 B intensity + 1 B classification + 1 B return + 2 B
// point source id).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace pointrast {

struct Bounds {
  glm::dvec3 min{std::numeric_limits<double>::infinity()};
  glm::dvec3 max{-std::numeric_limits<double>::infinity()};

  bool empty() const { return !(min.x <= max.x && min.y <= max.y && min.z <= max.z); }
  void expand(const glm::dvec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void expand(const Bounds& b) {
    if (b.empty()) return;
    expand(b.min);
    expand(b.max);
  }
  glm::dvec3 center() const { return empty() ? glm::dvec3(0) : 0.5 * (min + max); }
  glm::dvec3 size() const { return empty() ? glm::dvec3(0) : max - min; }
  double diagonal() const { return glm::length(size()); }
};

// Packed color: r | g << 8 | b << 16 | a << 24 (RGBA8, the byte order of a PNG row).
constexpr uint32_t packRgba(uint32_t r, uint32_t g, uint32_t b, uint32_t a = 255) {
  return r | (g << 8) | (b << 16) | (a << 24);
}

struct PointCloud {
  std::vector<int32_t> positions; // 3 per point: x, y, z quantized
  glm::dvec3 scale{0.001};
  glm::dvec3 offset{0.0};
  std::vector<uint32_t> colors;      // packRgba; empty if the source has none
  std::vector<uint16_t> intensity;   // empty if none
  std::vector<uint8_t> classification; // empty if none
  std::vector<uint8_t> returnNumber; // empty if none
  std::vector<uint16_t> pointSourceId; // empty if none (LAS: the flight line or scan a point came from)
  Bounds bounds;                     // of world positions, exact (computed from the points)
  std::string source;                // file name or scene description, for messages

  uint64_t size() const { return positions.size() / 3; }
  bool hasColor() const { return !colors.empty(); }

  glm::dvec3 world(uint64_t i) const {
    return {positions[3 * i] * scale.x + offset.x, positions[3 * i + 1] * scale.y + offset.y,
            positions[3 * i + 2] * scale.z + offset.z};
  }
  // The point float32 GPU coordinates are relative to: the center of the bounds.
  glm::dvec3 origin() const { return bounds.center(); }
};

// The largest coordinate magnitude pointrast renders: beyond it doubles are coarser than 1/8 unit, and no
// survey, scan or simulation has such values; they come from a damaged header or file.
constexpr double kMaxCoordinate = 1e15;
// Throws InputError naming `source` when bounds are not finite or reach beyond kMaxCoordinate. Empty
// bounds pass.
void checkCoordinateRange(const Bounds& bounds, const std::string& source);

// Recomputes cloud.bounds from the points (all hardware threads).
void computeBounds(PointCloud& cloud);

// Writes 3 floats per point for points [first, first + count): world(i) - origin, computed in double and
// rounded once to float. dst must hold 3 * count floats.
void toRelativeFloat(float* dst, const PointCloud& cloud, uint64_t first, uint64_t count,
                     const glm::dvec3& origin);

// Colors for display, one packRgba per point for [first, first + count): the cloud's RGB where it has
// a meaningful one, otherwise a ramp over intensity (if present and not constant) or elevation.
// hasUsableColor() tells which applies; it is false when colors exist but are all black (4_6_crop.las).
bool hasUsableColor(const PointCloud& cloud);
void displayColors(uint32_t* dst, const PointCloud& cloud, uint64_t first, uint64_t count);

// What displayColors() maps onto colors, decided from the whole cloud so every chunk of it gets the same
// ramp. Deciding costs a few milliseconds (ranges come from a regular sample of at most 2^20 points;
// only an all-black color array is scanned in full), so a caller converting a large cloud in many chunks
// should compute it once and pass it to the overload below rather than call the four-argument form.
// The palettes and ramps of each source are in cloud/attribute_colors.h.
struct DisplayColorMode {
  enum class Source { Rgb, Intensity, Elevation, Classification, ReturnNumber, PointSource };
  Source source = Source::Elevation;
  // Values mapped to the two ends of the ramp (intensity units or world z): the 0.5% and 99.5%
  // percentiles rather than min and max, so a few outliers (birds, noise) do not flatten the ramp.
  // Intensity counts as constant (elevation is used) when the sample shows one value.
  double lo = 0.0, hi = 1.0;
};
// The automatic choice: RGB where usable, else intensity where not constant, else elevation.
DisplayColorMode displayColorMode(const PointCloud& cloud);
// An explicit choice (render --color): throws InputError naming cloud.source when the cloud lacks the
// attribute. Intensity and elevation map [lo, hi] = `range` when given (lo < hi), else the robust
// percentiles above; the other sources ignore the range.
struct ColorRange {
  double lo = 0.0, hi = 0.0;
};
DisplayColorMode displayColorMode(const PointCloud& cloud, DisplayColorMode::Source source,
                                  std::optional<ColorRange> range = std::nullopt);
void displayColors(uint32_t* dst, const PointCloud& cloud, uint64_t first, uint64_t count,
                   const DisplayColorMode& mode);

} // namespace pointrast
