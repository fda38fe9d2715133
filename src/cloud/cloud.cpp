#include "cloud/cloud.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "base/error.h"
#include "base/parallel.h"
#include "cloud/attribute_colors.h"
#include "cloud/detail.h"

namespace pointrast {

void checkCoordinateRange(const Bounds& bounds, const std::string& source) {
  if (bounds.empty()) return;
  double reach = 0;
  for (const glm::dvec3& corner : {bounds.min, bounds.max})
    for (int a = 0; a < 3; ++a)
      reach = std::isfinite(corner[a]) ? std::max(reach, std::abs(corner[a])) : INFINITY;
  if (reach <= kMaxCoordinate) return;
  char text[200];
  std::snprintf(text, sizeof text,
                ": coordinates reach %.3g, beyond the %.0e pointrast renders (doubles are coarser than 1/8 "
                "there); a damaged header or file?",
                reach, kMaxCoordinate);
  throw InputError(source + text);
}

namespace detail {

namespace {
// 1 M points per block: large enough that thread start-up is noise, small enough to balance 2..128 cores.
constexpr uint64_t kBlock = uint64_t(1) << 20;
} // namespace

namespace {
using Int4 = int32_t __attribute__((vector_size(16)));

// The minimum and maximum of groups of four points (twelve coordinates, x y z x y z ...) in three vectors
// of four lanes each: lane l of vector j holds axis (4j + l) % 3. Where the CPU has AVX2 its clone runs.
__attribute__((target_clones("avx2", "default"))) void boxOfGroups(const int32_t* p, uint64_t groups,
                                                                   Int4 (&lo)[3], Int4 (&hi)[3]) {
  for (uint64_t g = 0; g < groups; ++g)
    for (int j = 0; j < 3; ++j) {
      Int4 v;
      std::memcpy(&v, p + 12 * g + 4 * j, sizeof v);
      lo[j] = v < lo[j] ? v : lo[j];
      hi[j] = v > hi[j] ? v : hi[j];
    }
}
} // namespace

QuantBox quantBox(const int32_t* positions, uint64_t first, uint64_t count) {
  QuantBox box;
  const int32_t* p = positions + 3 * first;
  if (const uint64_t groups = count / 4) {
    constexpr int32_t kLow = std::numeric_limits<int32_t>::min(), kHigh = std::numeric_limits<int32_t>::max();
    Int4 lo[3], hi[3];
    for (int j = 0; j < 3; ++j) {
      lo[j] = Int4{kHigh, kHigh, kHigh, kHigh};
      hi[j] = Int4{kLow, kLow, kLow, kLow};
    }
    boxOfGroups(p, groups, lo, hi);
    for (int l = 0; l < 12; ++l) {
      const int a = l % 3;
      box.min[a] = std::min(box.min[a], lo[l / 4][l % 4]);
      box.max[a] = std::max(box.max[a], hi[l / 4][l % 4]);
    }
    p += 12 * groups;
    count -= 4 * groups;
  }
  for (uint64_t i = 0; i < count; ++i, p += 3) {
    for (int a = 0; a < 3; ++a) {
      box.min[a] = std::min(box.min[a], p[a]);
      box.max[a] = std::max(box.max[a], p[a]);
    }
  }
  return box;
}

QuantBox quantBoxParallel(const int32_t* positions, uint64_t count) {
  std::vector<QuantBox> boxes((count + kBlock - 1) / kBlock);
  parallelBlocks(count, kBlock, [&](uint64_t block, uint64_t begin, uint64_t end) {
    boxes[block] = quantBox(positions, begin, end - begin);
  });
  QuantBox box;
  for (const QuantBox& b : boxes)
    box.expand(b);
  return box;
}

Bounds worldBounds(const QuantBox& box, const glm::dvec3& scale, const glm::dvec3& offset) {
  Bounds bounds;
  if (box.empty()) return bounds;
  // Both corners: with a negative scale the smallest q gives the largest world coordinate.
  bounds.expand(glm::dvec3(box.min[0] * scale.x + offset.x, box.min[1] * scale.y + offset.y,
                           box.min[2] * scale.z + offset.z));
  bounds.expand(glm::dvec3(box.max[0] * scale.x + offset.x, box.max[1] * scale.y + offset.y,
                           box.max[2] * scale.z + offset.z));
  return bounds;
}

namespace {
// Turbo, the polynomial approximation published with it (A. Mikhailov, "Turbo, An Improved Rainbow
// Colormap for Visualization", Google AI blog, 2019): perceptually smoother than jet, dark at both ends.
std::array<uint32_t, 256> makeTurbo() {
  std::array<uint32_t, 256> lut{};
  for (int i = 0; i < 256; ++i) {
    double x = i / 255.0, x2 = x * x, x3 = x2 * x, x4 = x2 * x2, x5 = x4 * x;
    double r = 0.13572138 + 4.61539260 * x - 42.66032258 * x2 + 132.13108234 * x3 - 152.94239396 * x4 +
               59.28637943 * x5;
    double g =
        0.09140261 + 2.19418839 * x + 4.84296658 * x2 - 14.18503333 * x3 + 4.27729857 * x4 + 2.82956604 * x5;
    double b = 0.10667330 + 12.64194608 * x - 60.58204836 * x2 + 110.36276771 * x3 - 89.90310912 * x4 +
               27.34824973 * x5;
    auto byte = [](double v) { return static_cast<uint32_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
    lut[i] = packRgba(byte(r), byte(g), byte(b));
  }
  return lut;
}
} // namespace

uint32_t rampColor(double t) {
  static const std::array<uint32_t, 256> kTurbo = makeTurbo();
  if (!(t > 0.0)) return kTurbo[0]; // also NaN
  if (t >= 1.0) return kTurbo[255];
  return kTurbo[static_cast<int>(t * 255.0 + 0.5)];
}

} // namespace detail

void computeBounds(PointCloud& cloud) {
  cloud.bounds = detail::worldBounds(detail::quantBoxParallel(cloud.positions.data(), cloud.size()),
                                     cloud.scale, cloud.offset);
}

void toRelativeFloat(float* dst, const PointCloud& cloud, uint64_t first, uint64_t count,
                     const glm::dvec3& origin) {
  assert(first + count <= cloud.size());
  const int32_t* src = cloud.positions.data();
  const glm::dvec3 s = cloud.scale, o = cloud.offset;
  // Each coordinate is the double world value minus the double origin, then a single rounding to float:
  // UTM northings (~4e6 m) keep their millimetres because they never pass through float on their own.
  auto convert = [&](uint64_t begin, uint64_t end) {
    for (uint64_t k = begin; k < end; ++k) {
      const int32_t* p = src + 3 * (first + k);
      dst[3 * k + 0] = static_cast<float>((p[0] * s.x + o.x) - origin.x);
      dst[3 * k + 1] = static_cast<float>((p[1] * s.y + o.y) - origin.y);
      dst[3 * k + 2] = static_cast<float>((p[2] * s.z + o.z) - origin.z);
    }
  };
  constexpr uint64_t kParallelFrom = uint64_t(1) << 18;
  if (count < kParallelFrom) {
    convert(0, count);
  } else {
    parallelBlocks(count, detail::kBlock,
                   [&](uint64_t, uint64_t begin, uint64_t end) { convert(begin, end); });
  }
}

bool hasUsableColor(const PointCloud& cloud) {
  const uint64_t n = cloud.colors.size();
  if (n == 0) return false;
  const uint32_t* c = cloud.colors.data();
  // Real colors show up in the first points; only an all-black cloud pays for the full parallel scan.
  constexpr uint64_t kQuick = 4096;
  for (uint64_t i = 0; i < std::min(n, kQuick); ++i)
    if (c[i] & 0x00FFFFFFu) return true;
  std::atomic<bool> found{false};
  parallelBlocks(n, detail::kBlock, [&](uint64_t, uint64_t begin, uint64_t end) {
    if (found.load(std::memory_order_relaxed)) return;
    for (uint64_t i = begin; i < end; ++i) {
      if (c[i] & 0x00FFFFFFu) {
        found = true;
        return;
      }
    }
  });
  return found;
}

namespace {

// displayColorMode() looks at a regular sample of at most this many points, serially: a few
// milliseconds whatever the cloud's size, so callers that convert chunk by chunk with the
// four-argument displayColors() (each call deciding the mode again) stay linear, and calls from inside
// parallelBlocks() start no threads of their own. A million samples pin the percentiles far closer than
// one ramp step.
constexpr uint64_t kModeSamples = uint64_t(1) << 20;

using Range = ColorRange;

// The 0.5% and 99.5% percentiles of value(k) over k in [0, n), from a histogram of 4096 bins between
// min and max (bin edges, so at most 1/4096 of the range off). Falls back to [min, max] when the
// percentiles coincide (most values equal).
template <class Value> Range robustRange(uint64_t n, double min, double max, Value value) {
  if (!(max > min)) return {min, max};
  constexpr int kBins = 4096;
  std::vector<uint64_t> hist(kBins, 0);
  const double toBin = kBins / (max - min);
  for (uint64_t k = 0; k < n; ++k) {
    // Clamped in double first: a span at the limits of double makes toBin infinite or zero, and the
    // product NaN or infinite, which no int holds. NaN falls into bin 0.
    const double bin = (value(k) - min) * toBin;
    ++hist[bin > 0 ? static_cast<int>(std::min(bin, double(kBins - 1))) : 0];
  }
  const uint64_t cut = n / 200; // 0.5%
  int loBin = 0, hiBin = kBins - 1;
  for (uint64_t acc = 0; loBin < kBins - 1 && acc + hist[loBin] <= cut; ++loBin)
    acc += hist[loBin];
  for (uint64_t acc = 0; hiBin > 0 && acc + hist[hiBin] <= cut; --hiBin)
    acc += hist[hiBin];
  Range r{min + loBin / toBin, min + (hiBin + 1) / toBin};
  if (!(r.hi > r.lo)) return {min, max};
  return {std::max(r.lo, min), std::min(r.hi, max)};
}

// Sample k of a mode's range is point k * stride.
struct Sampling {
  uint64_t stride = 1, samples = 0;
  explicit Sampling(uint64_t n)
      : stride(std::max<uint64_t>(1, (n + kModeSamples - 1) / kModeSamples)),
        samples((n + stride - 1) / stride) {}
};

// Robust range of the intensity sample; lo == hi when the sample shows one value.
Range intensityRange(const PointCloud& cloud) {
  const Sampling s(cloud.size());
  const uint16_t* v = cloud.intensity.data();
  uint16_t lo = 65535, hi = 0;
  for (uint64_t k = 0; k < s.samples; ++k) {
    lo = std::min(lo, v[k * s.stride]);
    hi = std::max(hi, v[k * s.stride]);
  }
  if (!(hi > lo)) return {double(lo), double(lo)};
  return robustRange(s.samples, lo, hi, [=](uint64_t k) { return double(v[k * s.stride]); });
}

// Robust range of world z over the sample; {0, 1} for a cloud without points.
Range elevationRange(const PointCloud& cloud) {
  const uint64_t n = cloud.size();
  Bounds b = cloud.bounds;
  if (b.empty() && n > 0)
    b = detail::worldBounds(detail::quantBox(cloud.positions.data(), 0, n), cloud.scale, cloud.offset);
  if (b.empty()) return {0.0, 1.0};
  const Sampling s(n);
  const int32_t* p = cloud.positions.data();
  const double sz = cloud.scale.z, oz = cloud.offset.z;
  return robustRange(s.samples, b.min.z, b.max.z,
                     [=](uint64_t k) { return p[3 * k * s.stride + 2] * sz + oz; });
}

} // namespace

DisplayColorMode displayColorMode(const PointCloud& cloud) {
  DisplayColorMode mode;
  if (hasUsableColor(cloud)) {
    mode.source = DisplayColorMode::Source::Rgb;
    return mode;
  }
  if (!cloud.intensity.empty()) {
    Range r = intensityRange(cloud);
    if (r.hi > r.lo) { // a constant intensity carries no picture: use elevation instead
      mode.source = DisplayColorMode::Source::Intensity;
      mode.lo = r.lo;
      mode.hi = r.hi;
      return mode;
    }
  }
  mode.source = DisplayColorMode::Source::Elevation;
  Range r = elevationRange(cloud);
  mode.lo = r.lo;
  mode.hi = r.hi;
  return mode;
}

DisplayColorMode displayColorMode(const PointCloud& cloud, DisplayColorMode::Source source,
                                  std::optional<ColorRange> range) {
  using Source = DisplayColorMode::Source;
  auto lacks = [&](const char* what) {
    return InputError(cloud.source + " has no " + what + " to color by (--color " + colorSourceName(source) +
                      ")");
  };
  DisplayColorMode mode;
  mode.source = source;
  const uint64_t n = cloud.size();
  switch (source) {
  case Source::Rgb:
    if (cloud.colors.size() != n) throw lacks("RGB colors");
    break;
  case Source::Intensity:
  case Source::Elevation: {
    if (source == Source::Intensity && cloud.intensity.size() != n) throw lacks("intensity");
    Range r = range                         ? Range{range->lo, range->hi}
              : source == Source::Intensity ? intensityRange(cloud)
                                            : elevationRange(cloud);
    mode.lo = r.lo;
    mode.hi = r.hi;
    break;
  }
  case Source::Classification:
    if (cloud.classification.size() != n) throw lacks("classification");
    break;
  case Source::ReturnNumber:
    if (cloud.returnNumber.size() != n) throw lacks("return numbers");
    break;
  case Source::PointSource:
    if (cloud.pointSourceId.size() != n) throw lacks("point source ids");
    break;
  }
  return mode;
}

void displayColors(uint32_t* dst, const PointCloud& cloud, uint64_t first, uint64_t count,
                   const DisplayColorMode& mode) {
  assert(first + count <= cloud.size());
  using Source = DisplayColorMode::Source;
  // An explicit mode was checked against the cloud (displayColorMode(cloud, source)); a mode handed in
  // for a cloud without the attribute is a caller's mistake.
  assert(mode.source != Source::Rgb || cloud.colors.size() == cloud.size());
  assert(mode.source != Source::Intensity || cloud.intensity.size() == cloud.size());
  assert(mode.source != Source::Classification || cloud.classification.size() == cloud.size());
  assert(mode.source != Source::ReturnNumber || cloud.returnNumber.size() == cloud.size());
  assert(mode.source != Source::PointSource || cloud.pointSourceId.size() == cloud.size());
  auto fill = [&](uint64_t begin, uint64_t end) {
    const int32_t* p = cloud.positions.data();
    const double sz = cloud.scale.z, oz = cloud.offset.z;
    if (mode.source == Source::Rgb) { // the common case, a loop the compiler can put in vector registers
      const uint32_t* colors = cloud.colors.data() + first;
      for (uint64_t k = begin; k < end; ++k)
        dst[k] = colors[k] | 0xFF000000u;
      return;
    }
    // Each case reads only its own attribute array: the others may be empty.
    for (uint64_t k = begin; k < end; ++k) {
      const uint64_t i = first + k;
      switch (mode.source) {
      case Source::Rgb:
        dst[k] = cloud.colors[i] | 0xFF000000u;
        break;
      case Source::Intensity:
        dst[k] = attributeColor(mode, 0, cloud.intensity[i], 0, 0, 0, 0);
        break;
      case Source::Elevation:
        dst[k] = attributeColor(mode, 0, 0, p[3 * i + 2] * sz + oz, 0, 0, 0);
        break;
      case Source::Classification:
        dst[k] = classificationColor(cloud.classification[i]);
        break;
      case Source::ReturnNumber:
        dst[k] = returnNumberColor(cloud.returnNumber[i]);
        break;
      case Source::PointSource:
        dst[k] = pointSourceColor(cloud.pointSourceId[i]);
        break;
      }
    }
  };
  constexpr uint64_t kParallelFrom = uint64_t(1) << 18;
  if (count < kParallelFrom) {
    fill(0, count);
  } else {
    parallelBlocks(count, detail::kBlock, [&](uint64_t, uint64_t begin, uint64_t end) { fill(begin, end); });
  }
}

void displayColors(uint32_t* dst, const PointCloud& cloud, uint64_t first, uint64_t count) {
  displayColors(dst, cloud, first, count, displayColorMode(cloud));
}

} // namespace pointrast
