// LAS writer: round trips through the reader for every flavor, and no output left behind on failure.
#include "io/io_test_util.h"
#include "io/writer.h"

using pointrast::InputError;
using pointrast::PointCloud;
using namespace pointrast::io;
using iotest::quiet;

namespace {

PointCloud makeCloud(uint64_t n, int maxReturn, int maxClass) {
  iotest::Lcg rng(42);
  PointCloud c;
  c.scale = glm::dvec3(0.01, 0.01, 0.001);
  c.offset = glm::dvec3(637000.0, 849000.0, -5.0);
  for (uint64_t i = 0; i < n; ++i) {
    // Include the int32 extremes: they must survive the round trip.
    int32_t x =
        i == 0 ? INT32_MIN : (i == 1 ? INT32_MAX : static_cast<int32_t>(rng.next() % 200000) - 100000);
    c.positions.push_back(x);
    c.positions.push_back(static_cast<int32_t>(rng.next() % 50000));
    c.positions.push_back(-static_cast<int32_t>(rng.next() % 1000));
    c.colors.push_back(pointrast::packRgba(rng.next() & 0xFF, rng.next() & 0xFF, rng.next() & 0xFF));
    c.intensity.push_back(static_cast<uint16_t>(rng.next()));
    c.classification.push_back(static_cast<uint8_t>(rng.next() % (maxClass + 1)));
    c.returnNumber.push_back(static_cast<uint8_t>(1 + rng.next() % maxReturn));
    c.pointSourceId.push_back(static_cast<uint16_t>(rng.next()));
  }
  c.bounds = pointrast::Bounds{};
  for (uint64_t i = 0; i < n; ++i)
    c.bounds.expand(c.world(i));
  return c;
}

struct FlavorCase {
  LasFlavor flavor;
  const char* detail;
  int maxReturn, maxClass;
};

class LasRoundTrip : public ::testing::TestWithParam<FlavorCase> {};

TEST_P(LasRoundTrip, ReadBackIsIdentical) {
  const FlavorCase& f = GetParam();
  iotest::TempDir dir;
  PointCloud cloud = makeCloud(3000, f.maxReturn, f.maxClass);
  auto path = dir / "out.las";
  writeLas(path, cloud, f.flavor);
  EXPECT_FALSE(std::filesystem::exists(dir / "out.las.partial"));
  PointCloud back = readCloud(path, quiet());
  EXPECT_EQ(back.positions, cloud.positions);
  EXPECT_EQ(back.scale, cloud.scale);
  EXPECT_EQ(back.offset, cloud.offset);
  EXPECT_EQ(back.colors, cloud.colors);
  EXPECT_EQ(back.intensity, cloud.intensity);
  EXPECT_EQ(back.classification, cloud.classification);
  EXPECT_EQ(back.returnNumber, cloud.returnNumber);
  EXPECT_EQ(back.pointSourceId, cloud.pointSourceId);
  EXPECT_EQ(back.bounds.min, cloud.bounds.min);
  EXPECT_EQ(back.bounds.max, cloud.bounds.max);

  FileInfo info = probeFile(path);
  EXPECT_EQ(info.formatDetail, f.detail);
  EXPECT_EQ(info.pointCount, cloud.size());
  EXPECT_EQ(info.colorBits, 16); // written as v * 257
  EXPECT_EQ(info.bounds.min, cloud.bounds.min);
  EXPECT_EQ(info.bounds.max, cloud.bounds.max);
}

INSTANTIATE_TEST_SUITE_P(
    Flavors, LasRoundTrip,
    ::testing::Values(FlavorCase{LasFlavor::Las12Pf2, "LAS 1.2, point format 2 (26 B records)", 5, 31},
                      FlavorCase{LasFlavor::Las12Pf3, "LAS 1.2, point format 3 (34 B records)", 5, 31},
                      FlavorCase{LasFlavor::Las14Pf7, "LAS 1.4, point format 7 (36 B records)", 15, 255}));

TEST(LasWriter, RealFileRoundTripsThroughEveryFlavor) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  iotest::TempDir dir;
  PointCloud original = readLas(iotest::data("las/autzen_trim.las"), quiet());
  for (LasFlavor flavor : {LasFlavor::Las12Pf2, LasFlavor::Las12Pf3, LasFlavor::Las14Pf7}) {
    writeLas(dir / "a.las", original, flavor);
    PointCloud back = readLas(dir / "a.las", quiet());
    EXPECT_EQ(back.positions, original.positions);
    EXPECT_EQ(back.colors, original.colors);
    EXPECT_EQ(back.bounds.min, original.bounds.min);
    EXPECT_EQ(back.bounds.max, original.bounds.max);
  }
}

TEST(LasWriter, HeaderCountsByReturn) {
  iotest::TempDir dir;
  PointCloud cloud = makeCloud(500, 5, 31);
  writeLas(dir / "a.las", cloud, LasFlavor::Las12Pf3);
  auto bytes = iotest::readBytes(dir / "a.las");
  ASSERT_EQ(bytes.size(), 227u + 500u * 34u);
  uint32_t count = 0, byReturn[5] = {}, expected[5] = {};
  std::memcpy(&count, bytes.data() + 107, 4);
  std::memcpy(byReturn, bytes.data() + 111, 20);
  for (uint8_t r : cloud.returnNumber)
    ++expected[r - 1];
  EXPECT_EQ(count, 500u);
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(byReturn[i], expected[i]);
}

TEST(LasWriter, EmptyAndColorlessClouds) {
  iotest::TempDir dir;
  PointCloud empty;
  writeLas(dir / "empty.las", empty, LasFlavor::Las14Pf7);
  EXPECT_EQ(readCloud(dir / "empty.las", quiet()).size(), 0u);

  PointCloud plain;
  plain.positions = {1, 2, 3, 4, 5, 6};
  writeLas(dir / "plain.las", plain, LasFlavor::Las12Pf2);
  PointCloud back = readCloud(dir / "plain.las", quiet());
  EXPECT_EQ(back.positions, plain.positions);
  ASSERT_EQ(back.colors.size(), 2u); // PF2 always has RGB: black
  EXPECT_EQ(back.colors[0], pointrast::packRgba(0, 0, 0));
  EXPECT_EQ(back.returnNumber, (std::vector<uint8_t>{1, 1}));
}

TEST(LasWriter, UnwritablePathLeavesNothingBehind) {
  iotest::TempDir dir;
  PointCloud cloud = makeCloud(10, 5, 31);
  auto missing = dir / "no-such-dir" / "a.las";
  EXPECT_THROW(writeLas(missing, cloud, LasFlavor::Las12Pf3), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "no-such-dir"));
  // The target is a directory: the data is written, the final rename fails, the partial file goes.
  std::filesystem::create_directory(dir / "taken.las");
  std::filesystem::create_directory(dir / "taken.las" / "child");
  try {
    writeLas(dir / "taken.las", cloud, LasFlavor::Las12Pf3);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("taken.las"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "taken.las.partial"));
  EXPECT_TRUE(std::filesystem::is_directory(dir / "taken.las" / "child"));
}

TEST(LasWriter, OverwritesAnExistingFileAtomically) {
  iotest::TempDir dir;
  iotest::writeText(dir / "a.las", "old");
  writeLas(dir / "a.las", makeCloud(5, 5, 31), LasFlavor::Las12Pf3);
  EXPECT_EQ(readCloud(dir / "a.las", quiet()).size(), 5u);
}

} // namespace
