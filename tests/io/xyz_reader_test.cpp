// XYZ / CSV / PTS text reader.
#include <cmath>
#include <set>
#include <vector>

#include "io/io_test_util.h"
#include "io/io_util.h"

using pointrast::InputError;
using pointrast::packRgba;
using pointrast::PointCloud;
using namespace pointrast::io;
using iotest::data;
using iotest::formatOf;
using iotest::quiet;

namespace {

PointCloud readText(const std::string& text, const std::string& name = "t.xyz") {
  iotest::TempDir dir;
  iotest::writeText(dir / name, text);
  return readCloud(dir / name, quiet());
}

std::string refusal(const std::string& text, const std::string& name = "t.csv") {
  iotest::TempDir dir;
  iotest::writeText(dir / name, text);
  std::string message;
  EXPECT_EQ(iotest::readOrRefuse(dir / name, &message), iotest::Outcome::Refused) << text;
  return message;
}

// The readers' quantization rounds inline; it must give what std::nearbyint (ties to even) and the clamp to
// int32 give: on ties, on values around the clamp and on random values at UTM scale.
TEST(Quantize, EqualsNearbyintAndClamp) {
  auto reference = [](double v, double scale, double offset) {
    double q = std::nearbyint((v - offset) / scale);
    q = q < -2147483648.0 ? -2147483648.0 : (q > 2147483647.0 ? 2147483647.0 : q);
    return static_cast<int32_t>(q);
  };
  std::vector<double> values = {0.0,
                                -0.0,
                                0.5,
                                1.5,
                                2.5,
                                -0.5,
                                -1.5,
                                -2.5,
                                0.49999999999999994,
                                2147483646.5,
                                2147483647.5,
                                2147483648.5,
                                1e12,
                                -2147483648.5,
                                -2147483649.5,
                                -1e12,
                                4503599627370495.5,
                                1e300,
                                -1e300};
  uint64_t state = 12345;
  for (int i = 0; i < 100000; ++i) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    values.push_back(double(state >> 11) * 0x1.0p-53 * 2e6 - 5e5 + 4.5e6); // northings
    values.push_back(double(int64_t(state >> 40) - (1 << 23)) * 0.5);      // halves
  }
  for (double scale : {1.0, 0.001, 0.01, 0.25})
    for (double offset : {0.0, 4.5e6, -12.5})
      for (double v : values)
        ASSERT_EQ(pointrast::io::detail::quantize(v, scale, offset), reference(v, scale, offset))
            << v << " scale " << scale << " offset " << offset;
}

TEST(XyzReader, GriddedDem) {
  POINTRAST_REQUIRE_DATA("xyz/data.xyz");
  EXPECT_EQ(formatOf(data("xyz/data.xyz")), "XYZ");
  PointCloud cloud = readCloud(data("xyz/data.xyz"), quiet());
  ASSERT_EQ(cloud.size(), 400u);
  EXPECT_FALSE(cloud.hasColor());
  const double lo[3] = {440750, 3750150, 74}, hi[3] = {441890, 3751290, 255};
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(cloud.bounds.min[a], lo[a], 1e-6);
    EXPECT_NEAR(cloud.bounds.max[a], hi[a], 1e-6);
  }
  EXPECT_NEAR(cloud.world(0).x, 440750, 1e-6);
  EXPECT_NEAR(cloud.world(0).y, 3751290, 1e-6);
  EXPECT_NEAR(cloud.world(0).z, 107, 1e-6);
  FileInfo info = probeFile(data("xyz/data.xyz"));
  EXPECT_STREQ(info.format->name, "XYZ");
  EXPECT_EQ(info.pointCount, 400u);
  EXPECT_EQ(info.formatDetail, "XYZ text, 3 columns (x y z)");
}

TEST(XyzReader, LeicaPts) {
  POINTRAST_REQUIRE_DATA("xyz/autzen.pts");
  PointCloud cloud = readCloud(data("xyz/autzen.pts"), quiet());
  ASSERT_EQ(cloud.size(), 10u);
  const double lo[3] = {636102.84, 848968.80, 427.92}, hi[3] = {636126.40, 849345.20, 512.14};
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(cloud.bounds.min[a], lo[a], 0.0051);
    EXPECT_NEAR(cloud.bounds.max[a], hi[a], 0.0051);
  }
  ASSERT_TRUE(cloud.hasColor());
  int cmin = 255, cmax = 0;
  for (uint32_t c : cloud.colors)
    for (int ch = 0; ch < 3; ++ch) {
      cmin = std::min<int>(cmin, iotest::channel(c, ch));
      cmax = std::max<int>(cmax, iotest::channel(c, ch));
    }
  EXPECT_EQ(cmin, 52);
  EXPECT_EQ(cmax, 128);
  EXPECT_EQ(cloud.colors[0], packRgba(52, 70, 64));
  // Signed PTS intensity -1613 is stored shifted by 2048.
  ASSERT_EQ(cloud.intensity.size(), 10u);
  EXPECT_EQ(cloud.intensity[0], 2048 - 1613);
  EXPECT_EQ(cloud.intensity[2], 2048 + 602);
  FileInfo info = probeFile(data("xyz/autzen.pts"));
  EXPECT_EQ(info.pointCount, 10u);
  EXPECT_TRUE(info.hasColor);
  EXPECT_EQ(info.colorBits, 8);
}

TEST(XyzReader, CsvWithHeaderCommentsAndBlankLines) {
  PointCloud cloud = readText("# exported by a test\r\n"
                              "x,y,z,r,g,b\r\n"
                              "// another comment\r\n"
                              "\r\n"
                              "1.5, 2.5, 3.5, 255, 0, 10\r\n"
                              "  -1;-2;-3;1;2;3  \r\n"
                              "+4\t5\t6e0\t7\t8\t9",
                              "t.csv");
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_NEAR(cloud.world(0).x, 1.5, 1e-9);
  EXPECT_NEAR(cloud.world(1).z, -3, 1e-9);
  EXPECT_NEAR(cloud.world(2).x, 4, 1e-9);
  EXPECT_EQ(cloud.colors,
            (std::vector<uint32_t>{packRgba(255, 0, 10), packRgba(1, 2, 3), packRgba(7, 8, 9)}));
}

TEST(XyzReader, ColumnLayouts) {
  PointCloud xyzi = readText("1 2 3 100\n4 5 6 200\n");
  EXPECT_FALSE(xyzi.hasColor());
  EXPECT_EQ(xyzi.intensity, (std::vector<uint16_t>{100, 200}));
  PointCloud floats = readText("1 2 3 1.0 0.5 0\n4 5 6 0.2 0 1\n");
  EXPECT_EQ(floats.colors, (std::vector<uint32_t>{packRgba(255, 128, 0), packRgba(51, 0, 255)}));
  PointCloud ints01 = readText("1 2 3 1 0 1\n"); // integers 0/1 are 8-bit values, not 0..1 floats
  EXPECT_EQ(ints01.colors.at(0), packRgba(1, 0, 1));
  PointCloud sixteen = readText("1 2 3 65535 256 0\n");
  EXPECT_EQ(sixteen.colors.at(0), packRgba(255, 1, 0));
  PointCloud extra = readText("1 2 3 0.1 0.2 0.3 9 9\n"); // 8 columns: x y z, rest ignored
  EXPECT_FALSE(extra.hasColor());
  EXPECT_EQ(extra.size(), 1u);
  PointCloud counted = readText("2\n1 2 3\n4 5 6\n1\n7 8 9\n", "t.pts"); // multi-scan PTS count lines
  EXPECT_EQ(counted.size(), 3u);
}

TEST(XyzReader, MalformedLinesNameTheLine) {
  std::string m = refusal("x y z\n1 2 3\n4 5 6\n7 eight 9\n");
  EXPECT_NE(m.find("line 4"), std::string::npos) << m;
  EXPECT_NE(m.find("'eight' is not a number"), std::string::npos) << m;
  m = refusal("1 2 3 4 5 6\n1 2 3\n");
  EXPECT_NE(m.find("line 2 has 3 values, but line 1 has 6"), std::string::npos) << m;
  m = refusal("1 2\n");
  EXPECT_NE(m.find("line 1 has 2 values"), std::string::npos) << m;
  m = refusal("# only a comment\n\n");
  EXPECT_NE(m.find("no point lines"), std::string::npos) << m;
  m = refusal("names\nmore names\n1 2 3\n");
  EXPECT_NE(m.find("line 2"), std::string::npos) << m;
  m = refusal(std::string(2 << 20, '1'));
  EXPECT_NE(m.find("longer than 1 MiB"), std::string::npos) << m;
}

TEST(XyzReader, NonFiniteRowsAreDropped) {
  PointCloud cloud = readText("1 2 3\nnan 0 0\n4 inf 6\n7 8 9\n");
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_NEAR(cloud.world(1).z, 9, 1e-9);
  iotest::TempDir dir;
  iotest::writeText(dir / "n.xyz", "1 2 3\nnan 0 0\n");
  bool listed = false;
  for (const auto& [key, value] : probeFile(dir / "n.xyz").extra)
    listed = listed || key.find("dropped") != std::string::npos;
  EXPECT_TRUE(listed);
}

// A NaN intensity has no integer value: converting it was undefined behaviour (UBSan float-cast-overflow;
// tests/fuzz/regressions/xyz holds the fuzzer's input). NaN and -inf read as 0, +inf as the largest value.
TEST(XyzReader, NonFiniteIntensitiesStayInRange) {
  PointCloud cloud = readText("1 2 3 NaN\n4 5 6 inf\n7 8 9 -inf\n1 1 1 70000\n");
  ASSERT_EQ(cloud.intensity.size(), 4u);
  EXPECT_EQ(cloud.intensity[0], 0);
  EXPECT_EQ(cloud.intensity[1], 65535);
  EXPECT_EQ(cloud.intensity[2], 0);
  EXPECT_EQ(cloud.intensity[3], 65535);
}

// Points a subnormal distance apart: the extent divided by the quantization steps is 0 and its log -inf,
// which was converted to an integer (undefined behaviour, found by xyz_fuzz). They read, in range.
TEST(XyzReader, SubnormalExtentIsQuantized) {
  PointCloud cloud = readText("0 0 0\n4.9e-322 0 0\n");
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_GT(cloud.scale.x, 0.0);
  EXPECT_LE(cloud.scale.x, 1e-299);
  EXPECT_TRUE(std::isfinite(cloud.bounds.max.x));
}

TEST(XyzReader, OnlyTextExtensionsAreTriedAsText) {
  iotest::TempDir dir;
  for (const char* name : {"a.xyz", "a.TXT", "a.csv", "a.pts"}) {
    iotest::writeText(dir / name, "1 2 3\n");
    EXPECT_EQ(formatOf(dir / name), "XYZ") << name;
  }
  iotest::writeText(dir / "a.dat", "1 2 3\n");
  EXPECT_EQ(formatOf(dir / "a.dat"), "");
  EXPECT_THROW(readCloud(dir / "a.dat", quiet()), InputError);
}

} // namespace

namespace {

// FileInfo::extra is also printed as a JSON object by `pointrast info --json`: keys must be unique.
TEST(Probe, ExtraKeysAreUniqueForEveryReadableFile) {
  POINTRAST_REQUIRE_DATA();
  for (const char* folder : {"las", "las/permutations", "ply", "xyz"})
    for (const auto& entry : std::filesystem::directory_iterator(data(folder))) {
      if (!entry.is_regular_file() || entry.path().extension() == ".py") continue;
      FileInfo info;
      try {
        info = probeFile(entry.path());
      } catch (const InputError&) {
        continue; // 1.2-no-points.las
      }
      std::set<std::string> keys;
      for (const auto& kv : info.extra)
        EXPECT_TRUE(keys.insert(kv.first).second) << entry.path() << ": " << kv.first;
      EXPECT_FALSE(info.formatDetail.empty()) << entry.path();
    }
}

} // namespace
