#include "cloud/cloud.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cloud/detail.h"
#include "test_clouds.h"

namespace pointrast {
namespace {

Bounds serialBounds(const PointCloud& cloud) {
  Bounds b;
  for (uint64_t i = 0; i < cloud.size(); ++i)
    b.expand(cloud.world(i));
  return b;
}

TEST(ComputeBounds, EqualsSerialMinMaxOfWorldPositions) {
  // More than one parallel block (1 M points) so the merge of block results is exercised.
  PointCloud cloud = testing::randomCloud(2'500'000, 2'000'000'000, {500000.0, 4000000.0, 100.0});
  Bounds ref = serialBounds(cloud);
  EXPECT_EQ(cloud.bounds.min, ref.min);
  EXPECT_EQ(cloud.bounds.max, ref.max);
}

TEST(ComputeBounds, NegativeAndMixedScales) {
  PointCloud cloud = testing::randomCloud(1000);
  cloud.scale = {-0.01, 0.5, -2.0};
  computeBounds(cloud);
  Bounds ref = serialBounds(cloud);
  EXPECT_EQ(cloud.bounds.min, ref.min);
  EXPECT_EQ(cloud.bounds.max, ref.max);
}

TEST(ComputeBounds, EmptyCloudHasEmptyBounds) {
  PointCloud cloud;
  computeBounds(cloud);
  EXPECT_TRUE(cloud.bounds.empty());
}

TEST(ToRelativeFloat, IsOneFloatRoundingOfTheDoubleDifference) {
  // UTM-size coordinates: 1 mm steps over +-1 km around (500 km, 4000 km).
  PointCloud cloud = testing::randomCloud(300'000, 1'000'000, {500000.0, 4000000.0, 250.0});
  const glm::dvec3 origin = cloud.origin();
  std::vector<float> rel(3 * cloud.size());
  toRelativeFloat(rel.data(), cloud, 0, cloud.size(), origin); // parallel path
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    glm::dvec3 d = cloud.world(i) - origin;
    for (int a = 0; a < 3; ++a) {
      ASSERT_EQ(rel[3 * i + a], static_cast<float>(d[a])) << "point " << i << " axis " << a;
      // Back in world units the error stays far below a millimetre (float ulp at 1 km is 61 um).
      ASSERT_LT(std::abs(double(rel[3 * i + a]) + origin[a] - cloud.world(i)[a]), 1e-4);
    }
  }
  // A sub-range through the serial path gives the same numbers.
  std::vector<float> part(3 * 1000);
  toRelativeFloat(part.data(), cloud, 12345, 1000, origin);
  for (int k = 0; k < 3000; ++k)
    ASSERT_EQ(part[k], rel[3 * 12345 + k]);
}

TEST(ToRelativeFloat, KeepsMillimetresWhereFloatWorldCoordinatesCannot) {
  // Two points 1 mm apart at a northing of 4000 km: in float world coordinates they coincide (the ulp
  // there is 0.5 m); relative to the origin in double they stay 1 mm apart.
  PointCloud cloud;
  cloud.offset = {500000.0, 4000000.0, 0.0};
  cloud.positions = {123, 456789, 1, 124, 456790, 2};
  computeBounds(cloud);
  EXPECT_EQ(static_cast<float>(cloud.world(0).y), static_cast<float>(cloud.world(1).y));
  float rel[6];
  toRelativeFloat(rel, cloud, 0, 2, cloud.origin());
  EXPECT_FLOAT_EQ(rel[4] - rel[1], 0.001f);
  EXPECT_FLOAT_EQ(rel[1], -0.0005f);
}

TEST(HasUsableColor, FalseWithoutColorsOrWhenAllBlack) {
  PointCloud cloud = testing::randomCloud(10'000);
  EXPECT_FALSE(hasUsableColor(cloud));
  cloud.colors.assign(cloud.size(), packRgba(0, 0, 0, 255)); // alpha alone does not count
  EXPECT_FALSE(hasUsableColor(cloud));
  cloud.colors.back() = packRgba(0, 0, 1); // past the quick check of the first points
  EXPECT_TRUE(hasUsableColor(cloud));
}

TEST(DisplayColors, UsesRgbWithOpaqueAlpha) {
  PointCloud cloud = testing::randomCloud(100);
  for (uint64_t i = 0; i < 100; ++i)
    cloud.colors.push_back(packRgba(uint32_t(i), 2, 3, 0));
  std::vector<uint32_t> out(100);
  displayColors(out.data(), cloud, 0, 100);
  for (uint32_t i = 0; i < 100; ++i)
    EXPECT_EQ(out[i], packRgba(i, 2, 3, 255));
}

TEST(DisplayColors, RampsOverIntensityThenElevation) {
  PointCloud cloud = testing::randomCloud(1000);
  cloud.colors.assign(1000, 0); // all black: ignored
  for (uint64_t i = 0; i < 1000; ++i)
    cloud.intensity.push_back(static_cast<uint16_t>(i * 10));
  DisplayColorMode mode = displayColorMode(cloud);
  EXPECT_EQ(mode.source, DisplayColorMode::Source::Intensity);
  std::vector<uint32_t> out(1000);
  displayColors(out.data(), cloud, 0, 1000);
  EXPECT_NE(out[0], out[999]);
  for (uint32_t c : out)
    EXPECT_EQ(c >> 24, 255u);
  // Chunks with the same mode give what the whole call gives.
  std::vector<uint32_t> chunk(300);
  displayColors(chunk.data(), cloud, 500, 300, mode);
  for (int k = 0; k < 300; ++k)
    EXPECT_EQ(chunk[k], out[500 + k]);

  cloud.intensity.assign(1000, 7); // constant intensity carries no information: elevation instead
  mode = displayColorMode(cloud);
  EXPECT_EQ(mode.source, DisplayColorMode::Source::Elevation);
  displayColors(out.data(), cloud, 0, 1000);
  uint64_t lowest = 0, highest = 0;
  for (uint64_t i = 0; i < 1000; ++i) {
    if (cloud.positions[3 * i + 2] < cloud.positions[3 * lowest + 2]) lowest = i;
    if (cloud.positions[3 * i + 2] > cloud.positions[3 * highest + 2]) highest = i;
  }
  EXPECT_NE(out[lowest], out[highest]);
}

TEST(DisplayColorMode, ElevationRangeIgnoresRareOutliers) {
  PointCloud cloud = testing::randomCloud(100'000, 10'000); // z within +-10 m
  cloud.positions[2] = 1'000'000;                           // one bird at 1 km
  computeBounds(cloud);
  DisplayColorMode mode = displayColorMode(cloud);
  EXPECT_EQ(mode.source, DisplayColorMode::Source::Elevation);
  EXPECT_LT(mode.lo, -9.0);
  EXPECT_GT(mode.hi, 9.0);
  EXPECT_LT(mode.hi, 20.0);
}

TEST(DisplayColorMode, LargeCloudRangeFromASample) {
  // Over 2^20 points the mode looks at every k-th point; the percentiles still land where they belong.
  PointCloud cloud = testing::randomCloud(2'500'000, 1000);
  cloud.intensity.resize(cloud.size());
  for (uint64_t i = 0; i < cloud.size(); ++i)
    cloud.intensity[i] = uint16_t(i * 7919 % 1000);
  DisplayColorMode mode = displayColorMode(cloud);
  EXPECT_EQ(mode.source, DisplayColorMode::Source::Intensity);
  EXPECT_NEAR(mode.lo, 5.0, 5.0);
  EXPECT_NEAR(mode.hi, 995.0, 5.0);
}

TEST(DisplayColorMode, FlatCloudDoesNotDivideByZero) {
  PointCloud cloud;
  cloud.positions = {1, 2, 3, 4, 5, 3};
  computeBounds(cloud);
  uint32_t out[2];
  displayColors(out, cloud, 0, 2);
  EXPECT_EQ(out[0], out[1]);
}

// Elevation spans at the limits of double (a subnormal scale; values of opposite sign near 1e308 whose
// difference overflows) make the histogram's bins infinitely narrow or wide: the bin of each value must
// still be found without converting NaN or infinity to an integer (undefined behaviour; the sanitized
// test build aborts on it).
TEST(DisplayColorMode, ExtremeElevationSpansStayDefined) {
  for (double scale : {1e-310, 8e298}) {
    SCOPED_TRACE(scale);
    PointCloud cloud;
    cloud.scale = glm::dvec3(1, 1, scale);
    cloud.positions = {0, 0, -2000000000, 1, 1, 0, 2, 2, 2000000000};
    computeBounds(cloud);
    uint32_t out[3];
    displayColors(out, cloud, 0, 3);
    if (scale < 1) {
      EXPECT_NE(out[0], out[2]); // the span itself is an ordinary number
    }
  }
}

} // namespace
} // namespace pointrast

// The box of a range of points, taken four points at a time with the rest one by one, is the minimum and
// maximum of each axis over exactly those points, whatever the range's start and length.
TEST(QuantBox, EqualsEachAxisMinimumAndMaximumOverTheRange) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 500; ++trial) {
    const uint64_t n = rng() % 60;
    std::vector<int32_t> positions(3 * n);
    for (int32_t& v : positions)
      v = int32_t(rng()) >> (rng() % 31); // both signs, small and large
    const uint64_t first = n ? rng() % n : 0, count = n - first - (n > first ? rng() % (n - first) : 0);
    const pointrast::detail::QuantBox box = pointrast::detail::quantBox(positions.data(), first, count);
    for (int a = 0; a < 3; ++a) {
      int32_t lo = std::numeric_limits<int32_t>::max(), hi = std::numeric_limits<int32_t>::min();
      for (uint64_t i = first; i < first + count; ++i) {
        lo = std::min(lo, positions[3 * i + a]);
        hi = std::max(hi, positions[3 * i + a]);
      }
      ASSERT_EQ(box.min[a], lo) << "trial " << trial << " axis " << a;
      ASSERT_EQ(box.max[a], hi) << "trial " << trial << " axis " << a;
    }
  }
}
