#include "cloud/order.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "base/error.h"
#include "test_clouds.h"

namespace pointrast {
namespace {

// Reference interleave, one bit at a time: bit 3k = x_k, 3k+1 = y_k, 3k+2 = z_k.
uint64_t slowMorton(uint32_t x, uint32_t y, uint32_t z) {
  uint64_t code = 0;
  for (int k = 0; k < 21; ++k) {
    code |= uint64_t((x >> k) & 1) << (3 * k);
    code |= uint64_t((y >> k) & 1) << (3 * k + 1);
    code |= uint64_t((z >> k) & 1) << (3 * k + 2);
  }
  return code;
}

// The Morton code of point i as the order header describes it: cells of the cubic bounds, 21 bits.
// Exact for dyadicCloud() below, where every quantity is a small binary fraction, so a cell boundary
// cannot round differently here and in the library.
std::vector<uint64_t> referenceCodes(const PointCloud& cloud) {
  const glm::dvec3 size = cloud.bounds.size();
  const double cube = std::max({size.x, size.y, size.z});
  std::vector<uint64_t> codes(cloud.size());
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    uint32_t c[3];
    for (int a = 0; a < 3; ++a) {
      double cell = cube > 0 ? (cloud.world(i)[a] - cloud.bounds.min[a]) / cube * double(1 << 21) : 0.0;
      c[a] = static_cast<uint32_t>(std::min(std::floor(cell), double((1 << 21) - 1)));
    }
    codes[i] = slowMorton(c[0], c[1], c[2]);
  }
  return codes;
}

// n points on a coarse grid (so many share a cell and ties occur) in a cube of exactly 1024 m: x and y
// steps of 2^-10 m, z steps of 2^-11 m, with point 1 pinned to the far corner of x. flatZ squeezes z.
PointCloud dyadicCloud(uint64_t n, uint64_t seed = 7, bool flatZ = false) {
  PointCloud cloud;
  cloud.scale = {1.0 / 1024, 1.0 / 1024, 1.0 / 2048};
  cloud.offset = {500000.0, 4000000.0, 0.0};
  std::mt19937_64 rng(seed);
  for (uint64_t i = 0; i < n; ++i) {
    cloud.positions.push_back(int32_t(rng() % 256) * 4096);
    cloud.positions.push_back(int32_t(rng() % 256) * 4096);
    cloud.positions.push_back(flatZ ? int32_t(rng() % 2048) : int32_t(rng() % 256) * 8192);
  }
  if (n > 1) cloud.positions[3] = 1 << 20;
  computeBounds(cloud);
  return cloud;
}

bool isPermutation(const std::vector<uint64_t>& order) {
  std::vector<bool> seen(order.size(), false);
  for (uint64_t v : order) {
    if (v >= order.size() || seen[v]) return false;
    seen[v] = true;
  }
  return true;
}

TEST(OrderNames, RoundTripAndHelpfulError) {
  for (Order o : {Order::Original, Order::Morton, Order::Shuffled, Order::ShuffledMorton})
    EXPECT_EQ(parseOrder(orderName(o)), o);
  EXPECT_STREQ(orderName(Order::ShuffledMorton), "shuffled-morton");
  try {
    parseOrder("zorder");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("zorder"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("shuffled-morton"), std::string::npos);
  }
}

TEST(MortonCode, KnownValues) {
  EXPECT_EQ(mortonCode(0, 0, 0), 0u);
  EXPECT_EQ(mortonCode(1, 0, 0), 1u);
  EXPECT_EQ(mortonCode(0, 1, 0), 2u);
  EXPECT_EQ(mortonCode(0, 0, 1), 4u);
  EXPECT_EQ(mortonCode(1, 1, 1), 7u);
  EXPECT_EQ(mortonCode(2, 0, 0), 8u);
  EXPECT_EQ(mortonCode(5, 0, 0), 0b1000001u);
  EXPECT_EQ(mortonCode(0, 3, 0), 0b10010u);
  const uint32_t m = (1u << 21) - 1;
  EXPECT_EQ(mortonCode(m, m, m), (uint64_t(1) << 63) - 1);
  EXPECT_EQ(mortonCode(m, 0, 0), 0x1249249249249249ull);
  EXPECT_EQ(mortonCode(0, 0, 1u << 20), uint64_t(1) << 62);
}

TEST(MortonCode, MatchesBitwiseInterleaveAndItsOrder) {
  std::mt19937_64 rng(3);
  uint64_t previousCode = 0, previousRef = 0;
  for (int k = 0; k < 100'000; ++k) {
    uint32_t x = rng() & 0x1fffff, y = rng() & 0x1fffff, z = rng() & 0x1fffff;
    if (k % 3 == 0) x &= 0xff, y &= 0xff, z &= 0xff; // small values too
    uint64_t code = mortonCode(x, y, z), ref = slowMorton(x, y, z);
    ASSERT_EQ(code, ref);
    // Code order is the lexicographic order of the interleaved bit strings.
    ASSERT_EQ(code < previousCode, ref < previousRef);
    previousCode = code;
    previousRef = ref;
  }
}

TEST(MortonCode, DecodeInvertsEncode) {
  std::mt19937_64 rng(4);
  for (int k = 0; k < 100'000; ++k) {
    const uint32_t x = rng() & 0x1fffff, y = rng() & 0x1fffff, z = rng() & 0x1fffff;
    uint32_t dx = 0, dy = 0, dz = 0;
    mortonDecode(mortonCode(x, y, z), dx, dy, dz);
    ASSERT_EQ(dx, x);
    ASSERT_EQ(dy, y);
    ASSERT_EQ(dz, z);
  }
  uint32_t x, y, z;
  mortonDecode(~uint64_t(0), x, y, z); // bit 63 is not part of a code
  EXPECT_EQ(x, 0x1fffffu);
  EXPECT_EQ(y, 0x1fffffu);
  EXPECT_EQ(z, 0x1fffffu);
}

class MortonOrder : public ::testing::TestWithParam<uint64_t> {};

TEST_P(MortonOrder, IsPermutationWithNonDecreasingCodesAndIndexTies) {
  PointCloud cloud = dyadicCloud(GetParam());
  std::vector<uint64_t> order;
  computeOrder(order, cloud, Order::Morton, 1);
  ASSERT_EQ(order.size(), cloud.size());
  ASSERT_TRUE(isPermutation(order));
  std::vector<uint64_t> codes = referenceCodes(cloud);
  for (uint64_t i = 1; i < order.size(); ++i) {
    ASSERT_LE(codes[order[i - 1]], codes[order[i]]) << "at " << i;
    if (codes[order[i - 1]] == codes[order[i]]) {
      ASSERT_LT(order[i - 1], order[i]) << "tie at " << i;
    }
  }
}

// 1000: single-threaded path; 150 001: bucketed parallel path.
INSTANTIATE_TEST_SUITE_P(Sizes, MortonOrder, ::testing::Values(0, 1, 2, 1000, 150'001));

TEST(MortonOrderTest, CubicCellsForAFlatCloud) {
  // A cloud 1024 m wide and 1 m high: with cubic cells its z cells are only 0..2047, so z matters only in
  // the low bits. Per-axis cells would spread z over all 21 bits and the order would differ.
  PointCloud cloud = dyadicCloud(5000, 5, /*flatZ=*/true);
  std::vector<uint64_t> order;
  computeOrder(order, cloud, Order::Morton, 1);
  std::vector<uint64_t> codes = referenceCodes(cloud);
  for (uint64_t i = 1; i < order.size(); ++i)
    ASSERT_LE(codes[order[i - 1]], codes[order[i]]);
}

// Scales a file's header may state: a subnormal one makes the cube subnormal and the cells per unit
// infinite; a huge one on an axis of zero extent then makes that axis's cell 0 x infinity = NaN, which no
// integer holds (undefined behaviour; the sanitized test build aborts on it). Cells at the limits of
// double must still order the points along the axis that varies.
TEST(MortonOrderTest, ScalesAtTheLimitsOfDouble) {
  PointCloud cloud;
  cloud.scale = glm::dvec3(1e-310, -6.7e97, 3.9e-313);
  cloud.positions = {0, 0, 1281517824, 0, 0, 0, 0, 0, 640000000};
  std::vector<uint64_t> order;
  computeOrder(order, cloud, Order::Morton, 1);
  EXPECT_EQ(order, (std::vector<uint64_t>{1, 2, 0}));
}

TEST(MortonOrderTest, IdenticalPointsKeepTheirOrder) {
  // Half the points on one spot (duplicates in a scan): the order must stay stable and complete.
  PointCloud cloud = dyadicCloud(200'000);
  for (uint64_t i = 2; i < cloud.size(); i += 2)
    cloud.positions[3 * i] = cloud.positions[3 * i + 1] = cloud.positions[3 * i + 2] = 4096;
  computeBounds(cloud);
  std::vector<uint64_t> order;
  computeOrder(order, cloud, Order::Morton, 1);
  ASSERT_TRUE(isPermutation(order));
  std::vector<uint64_t> codes = referenceCodes(cloud);
  for (uint64_t i = 1; i < order.size(); ++i) {
    ASSERT_LE(codes[order[i - 1]], codes[order[i]]);
    if (codes[order[i - 1]] == codes[order[i]]) {
      ASSERT_LT(order[i - 1], order[i]);
    }
  }
}

TEST(ShuffledOrder, DeterministicPerSeedDifferentAcrossSeeds) {
  for (uint64_t n : {uint64_t(1000), uint64_t(150'001)}) {
    PointCloud cloud = testing::randomCloud(n);
    std::vector<uint64_t> a, b, c;
    computeOrder(a, cloud, Order::Shuffled, 1);
    computeOrder(b, cloud, Order::Shuffled, 1);
    computeOrder(c, cloud, Order::Shuffled, 2);
    ASSERT_TRUE(isPermutation(a));
    ASSERT_TRUE(isPermutation(c));
    EXPECT_EQ(a, b);
    EXPECT_NE(a, c);
    // A uniform permutation moves an element by n/3 on average; fixed points are rare (~1).
    double moved = 0;
    uint64_t fixed = 0;
    for (uint64_t i = 0; i < n; ++i) {
      moved += std::abs(double(a[i]) - double(i));
      fixed += a[i] == i;
    }
    EXPECT_NEAR(moved / double(n) / double(n), 1.0 / 3.0, 0.02);
    EXPECT_LT(fixed, 10u);
  }
}

TEST(ShuffledOrder, DoesNotDependOnTheCoordinates) {
  PointCloud a = testing::randomCloud(5000, 10, glm::dvec3(0), 1);
  PointCloud b = testing::randomCloud(5000, 100000, glm::dvec3(0), 2);
  std::vector<uint64_t> oa, ob;
  computeOrder(oa, a, Order::Shuffled, 9);
  computeOrder(ob, b, Order::Shuffled, 9);
  EXPECT_EQ(oa, ob);
}

TEST(ShuffledMortonOrder, RunsAreWholeMortonRunsInOrder) {
  for (uint64_t n : {uint64_t(1), uint64_t(128), uint64_t(1000), uint64_t(150'037)}) {
    PointCloud cloud = testing::randomCloud(n);
    std::vector<uint64_t> morton, sm, again, other;
    computeOrder(morton, cloud, Order::Morton, 5);
    computeOrder(sm, cloud, Order::ShuffledMorton, 5);
    computeOrder(again, cloud, Order::ShuffledMorton, 5);
    computeOrder(other, cloud, Order::ShuffledMorton, 6);
    ASSERT_TRUE(isPermutation(sm));
    EXPECT_EQ(sm, again);
    if (n > 2 * kShuffleRun) {
      EXPECT_NE(sm, other);
    }
    // Where each point sits in the Morton order.
    std::vector<uint64_t> rank(n);
    for (uint64_t i = 0; i < n; ++i)
      rank[morton[i]] = i;
    // Walk the result run by run: each run starts at a multiple of kShuffleRun in the Morton order and
    // continues it point by point for a full run (or to the end of the cloud, for the short last run).
    std::vector<bool> runSeen((n + kShuffleRun - 1) / kShuffleRun, false);
    uint64_t i = 0;
    while (i < n) {
      uint64_t start = rank[sm[i]];
      ASSERT_EQ(start % kShuffleRun, 0u) << "run at " << i << " does not start a Morton run";
      ASSERT_FALSE(runSeen[start / kShuffleRun]);
      runSeen[start / kShuffleRun] = true;
      uint64_t length = std::min(kShuffleRun, n - start);
      for (uint64_t k = 0; k < length; ++k)
        ASSERT_EQ(rank[sm[i + k]], start + k);
      i += length;
    }
  }
}

TEST(ApplyOrder, KeepsAttributeRowsTogether) {
  PointCloud cloud;
  const uint64_t n = 70'000;
  for (uint64_t i = 0; i < n; ++i) {
    cloud.positions.insert(cloud.positions.end(), {int32_t(i), int32_t(2 * i), -int32_t(i)});
    cloud.colors.push_back(uint32_t(i * 7));
    cloud.intensity.push_back(uint16_t(i));
    cloud.classification.push_back(uint8_t(i * 3));
    cloud.returnNumber.push_back(uint8_t(i * 5));
  }
  computeBounds(cloud);
  const Bounds before = cloud.bounds;
  std::vector<uint64_t> order;
  computeOrder(order, cloud, Order::Shuffled, 3);
  applyOrder(cloud, order);
  ASSERT_EQ(cloud.size(), n);
  for (uint64_t k = 0; k < n; ++k) {
    const uint64_t i = order[k];
    ASSERT_EQ(cloud.positions[3 * k], int32_t(i));
    ASSERT_EQ(cloud.positions[3 * k + 1], int32_t(2 * i));
    ASSERT_EQ(cloud.positions[3 * k + 2], -int32_t(i));
    ASSERT_EQ(cloud.colors[k], uint32_t(i * 7));
    ASSERT_EQ(cloud.intensity[k], uint16_t(i));
    ASSERT_EQ(cloud.classification[k], uint8_t(i * 3));
    ASSERT_EQ(cloud.returnNumber[k], uint8_t(i * 5));
  }
  EXPECT_EQ(cloud.bounds.min, before.min);
}

TEST(OrderedCopy, EqualsApplyOrderAndLeavesTheSourceAlone) {
  PointCloud cloud = testing::randomCloud(20'000);
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    cloud.colors.push_back(uint32_t(i * 7));
    cloud.returnNumber.push_back(uint8_t(i));
  }
  const PointCloud original = cloud;
  std::vector<uint64_t> order;
  computeOrder(order, cloud, Order::ShuffledMorton, 4);
  const PointCloud copy = orderedCopy(cloud, order);
  applyOrder(cloud, order);
  EXPECT_EQ(copy.positions, cloud.positions);
  EXPECT_EQ(copy.colors, cloud.colors);
  EXPECT_EQ(copy.returnNumber, cloud.returnNumber);
  EXPECT_TRUE(copy.intensity.empty());
  EXPECT_EQ(copy.bounds.min, original.bounds.min);
  EXPECT_EQ(copy.bounds.max, original.bounds.max);
  EXPECT_EQ(copy.scale, original.scale);
  EXPECT_NE(copy.positions, original.positions);
}

TEST(ApplyOrder, LeavesMissingAttributesEmpty) {
  PointCloud cloud = testing::randomCloud(1000);
  reorder(cloud, Order::Morton, 1);
  EXPECT_EQ(cloud.size(), 1000u);
  EXPECT_TRUE(cloud.colors.empty());
  EXPECT_TRUE(cloud.intensity.empty());
}

TEST(Reorder, OriginalIsANoOpAndMortonSortsTheCloud) {
  PointCloud cloud = dyadicCloud(20'000);
  PointCloud copy = cloud;
  reorder(cloud, Order::Original, 1);
  EXPECT_EQ(cloud.positions, copy.positions);
  reorder(cloud, Order::Morton, 1);
  std::vector<uint64_t> codes = referenceCodes(cloud);
  for (uint64_t i = 1; i < codes.size(); ++i)
    ASSERT_LE(codes[i - 1], codes[i]);
}

} // namespace
} // namespace pointrast
