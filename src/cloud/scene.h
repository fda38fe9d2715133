// The procedural scenes behind generateScene(), not part of the library's interface (tests use it to
// check that every point is a pure function of its index).
//
// A scene is prepared once from (points, seed) (sizes, layout) and then writes any index range of
// points independently. Every point is a pure function of (scene, points, seed, index): randomness
// comes from hashes of the index and of grid-cell coordinates, never from a stream shared between
// points, so the result does not depend on how ranges are cut or on how many threads write them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

#include "cloud/detail.h"
#include "cloud/generate.h"

namespace pointrast::detail {

class SceneGenerator {
public:
  virtual ~SceneGenerator() = default;
  // Writes points [first, first + count): positions[3k..3k+2] (quantized, see scale/offset) and
  // colors[k] for point first + k, and their ASPRS classes[k] when `classes` is not null.
  virtual void generate(uint64_t first, uint64_t count, int32_t* positions, uint32_t* colors,
                        uint8_t* classes) const = 0;

  // Quantization of the scene: world = q * scale + offset. 1 mm, with a UTM-like offset so the
  // double-precision origin path is exercised as with real survey data.
  static constexpr double kScale = 0.001;
  glm::dvec3 offset{500000.0, 4000000.0, 0.0};
};

std::unique_ptr<SceneGenerator> makeTerrainScene(uint64_t points, uint64_t seed);
std::unique_ptr<SceneGenerator> makeTlsScene(uint64_t points, uint64_t seed);
std::unique_ptr<SceneGenerator> makeScene(Scene scene, uint64_t points, uint64_t seed);

// ---- helpers shared by the scenes ---------------------------------------------------------------

// Hash of 2D integer cell coordinates (a murmur3-style finalizer over a linear combination): cheap,
// and with no visible lattice artefacts in value noise.
inline uint32_t hash2(int32_t x, int32_t y, uint32_t salt) {
  uint32_t h = static_cast<uint32_t>(x) * 0x8da6b343u ^ static_cast<uint32_t>(y) * 0xd8163841u ^ salt;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}
inline uint32_t hash1(int32_t x, uint32_t salt) {
  return hash2(x, 0x5bd1e995, salt);
}

// floor() as an integer, for |v| < 2^31. std::floor is a library call on baseline x86-64 (no SSE4.1
// roundsd), and the scenes take several per point.
inline int32_t floorInt(double v) {
  const int32_t i = static_cast<int32_t>(v);
  return i - (v < static_cast<double>(i) ? 1 : 0);
}

// [0, 1) from the top 24 bits of a hash.
inline double unit(uint32_t h) {
  return (h >> 8) * (1.0 / 16777216.0);
}
// [0, 1) from bits [shift, shift + 16) of a 64-bit random value.
inline double unit16(uint64_t r, int shift) {
  return ((r >> shift) & 0xffff) * (1.0 / 65536.0);
}

// Value noise on a unit lattice with smoothstep interpolation, in [-1, 1], with its gradient
// (Perlin, "An image synthesizer", SIGGRAPH 1985, the value-noise variant).
struct NoiseSample {
  double v, dx, dy;
};

// The lattice values around one cell. Successive pulses of a scan line are centimetres apart, so they
// almost always fall in the cell of the previous one: caching its four hashed corners removes nearly
// all hashing from the coarse octaves. Results are identical with or without the cache.
struct NoiseCell {
  int32_t ix = 0, iy = 0;
  bool valid = false;
  double a = 0, b = 0, c = 0, d = 0;
};

inline NoiseSample valueNoise(double x, double y, uint32_t salt, NoiseCell& cell) {
  const int32_t ix = floorInt(x), iy = floorInt(y);
  if (!cell.valid || cell.ix != ix || cell.iy != iy) {
    cell.ix = ix;
    cell.iy = iy;
    cell.valid = true;
    cell.a = unit(hash2(ix, iy, salt)) * 2 - 1;
    cell.b = unit(hash2(ix + 1, iy, salt)) * 2 - 1;
    cell.c = unit(hash2(ix, iy + 1, salt)) * 2 - 1;
    cell.d = unit(hash2(ix + 1, iy + 1, salt)) * 2 - 1;
  }
  const double tx = x - ix, ty = y - iy;
  const double sx = tx * tx * (3 - 2 * tx), sy = ty * ty * (3 - 2 * ty);
  const double a = cell.a, b = cell.b, c = cell.c, d = cell.d, k = a - b - c + d;
  return {a + (b - a) * sx + (c - a) * sy + k * sx * sy, 6 * tx * (1 - tx) * ((b - a) + k * sy),
          6 * ty * (1 - ty) * ((c - a) + k * sx)};
}

inline NoiseSample valueNoise(double x, double y, uint32_t salt) {
  NoiseCell cell;
  return valueNoise(x, y, salt, cell);
}

struct Rgb {
  double r, g, b;
  Rgb operator*(double s) const { return {r * s, g * s, b * s}; }
  Rgb operator+(const Rgb& o) const { return {r + o.r, g + o.g, b + o.b}; }
};
inline Rgb mix(const Rgb& a, const Rgb& b, double t) {
  return a * (1 - t) + b * t;
}
inline uint32_t toRgba(const Rgb& c) {
  auto byte = [](double v) { return static_cast<uint32_t>(std::clamp(v, 0.0, 255.0) + 0.5); };
  return packRgba(byte(c.r), byte(c.g), byte(c.b));
}

// Scene metres (relative to the offset) to quantization steps of SceneGenerator::kScale (1 mm).
inline int32_t quantize(double v) {
  return floorInt(v * 1000.0 + 0.5);
}

} // namespace pointrast::detail
