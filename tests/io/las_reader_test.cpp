// LAS reader against the real files in shared/data/las (expected values from shared/data/README.md).
#include <cmath>

#include "io/io_test_util.h"
#include "io/las/las_format.h"
#include "io/writer.h"

using pointrast::InputError;
using pointrast::PointCloud;
using namespace pointrast::io;
using iotest::channel;
using iotest::data;
using iotest::formatOf;
using iotest::quiet;

namespace {

enum class Color { None, Bits8, Bits16, Zero };

struct LasCase {
  const char* file;
  uint64_t count;
  double min[3], max[3];
  Color color;
  int colorLo, colorHi; // raw file values (16-bit values for 16-bit files)
};

const LasCase kCases[] = {
    {"las/autzen_trim.las",
     110000,
     {636001.76, 848935.20, 406.26},
     {637179.22, 849497.90, 520.51},
     Color::Bits8,
     40,
     236},
    {"las/autzen_trim_7.las",
     110000,
     {636001.76, 848935.20, 406.26},
     {637179.22, 849497.90, 520.51},
     Color::Bits8,
     40,
     236},
    {"las/1.2-with-color.las",
     1065,
     {635619.85, 848899.70, 406.59},
     {638982.55, 853535.43, 586.38},
     Color::Bits8,
     39,
     249},
    {"las/autzen-thin.las",
     10653,
     {635589.01, 848886.45, 406.59},
     {638994.75, 853535.43, 593.73},
     Color::Bits8,
     39,
     254},
    {"las/sample_c.las",
     14408,
     {674521.92, 1206740.08, 627.53},
     {674605.32, 1206814.96, 656.23},
     Color::Bits16,
     35840,
     54272},
    {"las/warsaw_small.las",
     3000,
     {639913.26, 485143.14, 84.70},
     {639946.75, 485175.91, 104.55},
     Color::Bits16,
     9728,
     53760},
    {"las/4_6_crop.las",
     23875,
     {1639600.00, 1454500.02, 7077.92},
     {1639799.98, 1454700.00, 7139.70},
     Color::Zero,
     0,
     0},
    {"las/extrabytes.las",
     1065,
     {635619.85, 848899.70, 406.59},
     {638982.55, 853535.43, 586.38},
     Color::Bits8,
     39,
     249},
    {"las/test1_4.las",
     1000,
     {1694038.45, 1816492.71, 5592.75},
     {1694539.68, 1816497.98, 5599.07},
     Color::None,
     0,
     0},
    {"las/epsg_4326.las",
     5380,
     {-94.683465, 31.036734, 39.08},
     {-94.660631, 31.047329, 78.12},
     Color::None,
     0,
     0},
    {"las/mvk-thin.las",
     6280,
     {2045001.76, 1267501.19, 95.79},
     {2049993.92, 1272499.79, 228.73},
     Color::None,
     0,
     0},
    {"las/hexbin-crop.las",
     38367,
     {393775.82, 3689071.94, 3107.86},
     {394069.24, 3689273.10, 3209.32},
     Color::None,
     0,
     0},
};

class LasFiles : public ::testing::TestWithParam<LasCase> {};

TEST_P(LasFiles, CountBoundsAndColors) {
  POINTRAST_REQUIRE_DATA();
  const LasCase& c = GetParam();
  PointCloud cloud = readCloud(data(c.file), quiet());
  EXPECT_EQ(cloud.size(), c.count);
  EXPECT_EQ(cloud.source, std::filesystem::path(c.file).filename().string());
  // README bounds are rounded to 2 decimals.
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(cloud.bounds.min[a], c.min[a], 0.0051) << "axis " << a;
    EXPECT_NEAR(cloud.bounds.max[a], c.max[a], 0.0051) << "axis " << a;
  }
  // Bounds are exact: every point inside, each face touched.
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    lo = glm::min(lo, cloud.world(i));
    hi = glm::max(hi, cloud.world(i));
  }
  EXPECT_EQ(lo, cloud.bounds.min);
  EXPECT_EQ(hi, cloud.bounds.max);

  EXPECT_EQ(cloud.hasColor(), c.color != Color::None);
  FileInfo info = probeFile(data(c.file));
  EXPECT_STREQ(info.format->name, "LAS");
  EXPECT_EQ(info.pointCount, c.count);
  EXPECT_TRUE(info.boundsFromHeader);
  EXPECT_EQ(info.hasColor, c.color != Color::None);
  if (c.color == Color::None) return;
  EXPECT_EQ(info.colorBits, c.color == Color::Bits16 ? 16 : 8);
  int lo8 = 255, hi8 = 0;
  for (uint32_t rgba : cloud.colors) {
    for (int ch = 0; ch < 3; ++ch) {
      lo8 = std::min<int>(lo8, channel(rgba, ch));
      hi8 = std::max<int>(hi8, channel(rgba, ch));
    }
    ASSERT_EQ(channel(rgba, 3), 255);
  }
  int shift = c.color == Color::Bits16 ? 8 : 0;
  EXPECT_EQ(lo8, c.colorLo >> shift);
  EXPECT_EQ(hi8, c.colorHi >> shift);
}

INSTANTIATE_TEST_SUITE_P(Data, LasFiles, ::testing::ValuesIn(kCases), [](const auto& param) {
  std::string name = std::filesystem::path(param.param.file).stem().string();
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
});

void expectSamePoints(const PointCloud& a, const PointCloud& b) {
  ASSERT_EQ(a.size(), b.size());
  for (uint64_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.world(i), b.world(i)) << "point " << i;
    ASSERT_EQ(a.colors[i], b.colors[i]) << "point " << i;
  }
}

TEST(LasReader, Pf7TwinEqualsPf3PointByPoint) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  PointCloud pf3 = readLas(data("las/autzen_trim.las"), quiet());
  PointCloud pf7 = readLas(data("las/autzen_trim_7.las"), quiet());
  expectSamePoints(pf3, pf7);
  EXPECT_EQ(pf3.intensity, pf7.intensity);
  EXPECT_EQ(pf3.returnNumber, pf7.returnNumber);
  // The point source id sits at byte 18 in PF3 and 20 in PF7; autzen_trim has one flight line.
  ASSERT_EQ(pf3.pointSourceId.size(), pf3.size());
  EXPECT_EQ(pf3.pointSourceId, pf7.pointSourceId);
  EXPECT_EQ(pf3.pointSourceId.front(), 7326);
}

TEST(LasReader, ExtraBytesStepByRecordLength) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  PointCloud plain = readLas(data("las/1.2-with-color.las"), quiet());
  PointCloud extra = readLas(data("las/extrabytes.las"), quiet());
  expectSamePoints(plain, extra);
  EXPECT_EQ(plain.intensity, extra.intensity);
  EXPECT_EQ(plain.classification, extra.classification);
  EXPECT_EQ(plain.returnNumber, extra.returnNumber);
  FileInfo info = probeFile(data("las/extrabytes.las"));
  EXPECT_NE(info.formatDetail.find("34 + 27 extra bytes"), std::string::npos) << info.formatDetail;
}

TEST(LasReader, Epsg4326BoundsToMicroDegrees) {
  POINTRAST_REQUIRE_DATA("las/epsg_4326.las");
  PointCloud cloud = readLas(data("las/epsg_4326.las"), quiet());
  EXPECT_NEAR(cloud.bounds.min.x, -94.683465, 1e-6);
  EXPECT_NEAR(cloud.bounds.min.y, 31.036734, 1e-6);
  EXPECT_NEAR(cloud.bounds.max.x, -94.660631, 1e-6);
  EXPECT_NEAR(cloud.bounds.max.y, 31.047329, 1e-6);
  EXPECT_EQ(cloud.scale, glm::dvec3(1e-7));
}

TEST(LasReader, Pf6OddScalesKeptExactly) {
  POINTRAST_REQUIRE_DATA("las/test1_4.las");
  PointCloud cloud = readLas(data("las/test1_4.las"), quiet());
  EXPECT_EQ(cloud.scale.x, 1.16451354e-06);
  EXPECT_EQ(cloud.offset.x, 1692500.352);
  FileInfo info = probeFile(data("las/test1_4.las"));
  EXPECT_NE(info.formatDetail.find("LAS 1.4, point format 6 (30 B records)"), std::string::npos)
      << info.formatDetail;
}

TEST(LasReader, NoPointsLoadsEmpty) {
  POINTRAST_REQUIRE_DATA("las/no-points.las");
  PointCloud cloud = readCloud(data("las/no-points.las"), quiet());
  EXPECT_EQ(cloud.size(), 0u);
  EXPECT_TRUE(cloud.bounds.empty());
  EXPECT_EQ(probeFile(data("las/no-points.las")).pointCount, 0u);
}

TEST(LasReader, VersionAndFormatPermutations) {
  POINTRAST_REQUIRE_DATA("las/permutations/1.0_0.las");
  const char* files[] = {"1.0_0", "1.0_1", "1.1_0", "1.1_1", "1.2_0", "1.2_1", "1.2_2", "1.2_3"};
  for (const char* name : files) {
    SCOPED_TRACE(name);
    PointCloud cloud = readCloud(data(std::string("las/permutations/") + name + ".las"), quiet());
    ASSERT_EQ(cloud.size(), 1u);
    glm::dvec3 p = cloud.world(0);
    EXPECT_NEAR(p.x, 470692.44, 1e-9);
    EXPECT_NEAR(p.y, 4602888.90, 1e-9);
    EXPECT_NEAR(p.z, 16.00, 1e-9);
    bool color = name[4] == '2' || name[4] == '3';
    ASSERT_EQ(cloud.hasColor(), color);
    if (color) {
      EXPECT_EQ(cloud.colors[0], pointrast::packRgba(255, 12, 234));
    }
  }
  // 1.0_0.las has 2 pad bytes before the points and a point that is "return 2 of 0".
  PointCloud padded = readLas(data("las/permutations/1.0_0.las"), quiet());
  EXPECT_EQ(padded.returnNumber.at(0), 2);
}

TEST(LasReader, HeaderClaimingMissingPointsIsRefused) {
  POINTRAST_REQUIRE_DATA("las/permutations/1.2-no-points.las");
  try {
    readCloud(data("las/permutations/1.2-no-points.las"), quiet());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("1.2-no-points.las"), std::string::npos) << m;
    EXPECT_NE(m.find("1065 points of 34 bytes"), std::string::npos) << m;
    EXPECT_NE(m.find("0 bytes of point data"), std::string::npos) << m;
  }
  EXPECT_THROW(probeFile(data("las/permutations/1.2-no-points.las")), InputError);
}

TEST(LasReader, AttributesKeptOrDropped) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  PointCloud with = readLas(data("las/1.2-with-color.las"), quiet());
  ASSERT_EQ(with.intensity.size(), with.size());
  ASSERT_EQ(with.classification.size(), with.size());
  ASSERT_EQ(with.returnNumber.size(), with.size());
  for (uint8_t r : with.returnNumber)
    EXPECT_LE(r, 7);
  ReadOptions options = quiet();
  options.keepAttributes = false;
  PointCloud without = readLas(data("las/1.2-with-color.las"), options);
  EXPECT_TRUE(without.intensity.empty());
  EXPECT_TRUE(without.classification.empty());
  EXPECT_TRUE(without.returnNumber.empty());
  EXPECT_TRUE(without.pointSourceId.empty());
  EXPECT_EQ(with.positions, without.positions);
  EXPECT_EQ(with.colors, without.colors);
}

TEST(LasReader, ProbeDescribesHeader) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  FileInfo info = probeFile(data("las/autzen_trim.las"));
  EXPECT_EQ(info.formatDetail, "LAS 1.2, point format 3 (34 B records)");
  EXPECT_EQ(info.scale, glm::dvec3(0.01));
  EXPECT_NEAR(info.bounds.min.x, 636001.76, 1e-6);
  EXPECT_NEAR(info.bounds.max.z, 520.51, 1e-6);
  std::string all;
  for (const auto& [key, value] : info.extra)
    all += key + "=" + value + "\n";
  EXPECT_NE(all.find("generating software=PDAL 1.0.0 (9e8465)"), std::string::npos) << all;
  EXPECT_NE(all.find("VLRs=5: LASF_Projection 34735"), std::string::npos) << all;
  EXPECT_NE(all.find("color values=40 .. 236"), std::string::npos) << all;
  EXPECT_NE(all.find("creation date=2015-09-10 (day 253)"), std::string::npos) << all;
}

// Small chunks cross chunk boundaries (and the read-ahead thread) with the real files, and the 8-bit
// -> 16-bit decision taken late in a file must recolor the earlier chunks.
TEST(LasReader, ChunkBoundariesGiveTheSameCloud) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  PointCloud whole = readLas(data("las/autzen_trim.las"), quiet());
  PointCloud sample16 = readLas(data("las/sample_c.las"), quiet());
  // Record-multiple and odd sizes; 1 byte still reads one record per chunk.
  for (uint64_t bytes : {34 * 1000 + 5, 34 * 20000}) {
    pointrast::io::detail::setLasChunkBytes(bytes);
    PointCloud chunked = readLas(data("las/autzen_trim.las"), quiet());
    pointrast::io::detail::setLasChunkBytes(0);
    EXPECT_EQ(whole.positions, chunked.positions);
    EXPECT_EQ(whole.colors, chunked.colors);
    EXPECT_EQ(whole.intensity, chunked.intensity);
    EXPECT_EQ(whole.bounds.min, chunked.bounds.min);
    EXPECT_EQ(whole.bounds.max, chunked.bounds.max);
  }
  for (uint64_t bytes : {1, 34 * 7, 34 * 1000}) {
    pointrast::io::detail::setLasChunkBytes(bytes);
    PointCloud chunked16 = readLas(data(bytes == 1 ? "las/1.2-with-color.las" : "las/sample_c.las"), quiet());
    pointrast::io::detail::setLasChunkBytes(0);
    EXPECT_EQ(bytes == 1 ? readLas(data("las/1.2-with-color.las"), quiet()).colors : sample16.colors,
              chunked16.colors);
  }
}

TEST(LasReader, LateSixteenBitValueRecolorsEarlierChunks) {
  // A PF2 file whose first points have 8-bit-looking values (all <= 255) and whose last point has 65535:
  // by the per-file rule the file is 16-bit, so the early points are near-black (v >> 8 == 0).
  iotest::TempDir dir;
  PointCloud cloud;
  cloud.scale = glm::dvec3(0.01);
  const int n = 100;
  for (int i = 0; i < n; ++i) {
    cloud.positions.insert(cloud.positions.end(), {i, 2 * i, 3 * i});
    cloud.colors.push_back(pointrast::packRgba(200, 100, 50));
  }
  writeLas(dir / "a.las", cloud, LasFlavor::Las12Pf2);
  // Patch raw 16-bit colors: 200 / 100 / 50 for every point but the last, which gets 65535.
  auto bytes = iotest::readBytes(dir / "a.las");
  for (int i = 0; i < n; ++i) {
    uint8_t* rgb = bytes.data() + 227 + 26 * i + 20;
    uint16_t v[3] = {200, 100, 50};
    if (i == n - 1) v[0] = v[1] = v[2] = 65535;
    std::memcpy(rgb, v, 6);
  }
  iotest::writeBytes(dir / "a.las", bytes);
  for (uint64_t chunk : {uint64_t(0), uint64_t(26 * 10)}) {
    pointrast::io::detail::setLasChunkBytes(chunk);
    PointCloud back = readLas(dir / "a.las", quiet());
    pointrast::io::detail::setLasChunkBytes(0);
    ASSERT_EQ(back.size(), uint64_t(n));
    for (int i = 0; i < n - 1; ++i)
      ASSERT_EQ(back.colors[i], pointrast::packRgba(0, 0, 0)) << i;
    EXPECT_EQ(back.colors[n - 1], pointrast::packRgba(255, 255, 255));
    EXPECT_EQ(probeFile(dir / "a.las").colorBits, 16);
  }
}

TEST(LasReader, CompressedFilesGoToTheLazReader) {
  POINTRAST_REQUIRE_DATA();
  for (const char* file : {"laz/autzen_trim.laz", "laz/simple.laz", "laz/lone-star.copc.laz"}) {
    SCOPED_TRACE(file);
    EXPECT_EQ(formatOf(data(file)), std::string(file).find("copc") != std::string::npos ? "COPC" : "LAZ");
    EXPECT_GT(readCloud(data(file), quiet()).size(), 0u);
    EXPECT_EQ(probeFile(data(file)).format, pointrast::io::detectFormat(data(file)));
    // The plain LAS reader refuses them with one line.
    try {
      readLas(data(file), quiet());
      ADD_FAILURE() << "expected InputError";
    } catch (const InputError& e) {
      std::string m = e.what();
      EXPECT_NE(m.find("LAZ"), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
}

TEST(LasReader, ContentDecidesNotTheExtension) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  iotest::TempDir dir;
  std::filesystem::copy_file(data("las/1.2-with-color.las"), dir / "looks.laz");
  EXPECT_EQ(formatOf(dir / "looks.laz"), "LAS");
  EXPECT_EQ(readCloud(dir / "looks.laz", quiet()).size(), 1065u);
  // A compression bit in the point format byte makes a .las file LAZ.
  auto bytes = iotest::readBytes(data("las/1.2-with-color.las"));
  bytes[104] |= 0x80;
  iotest::writeBytes(dir / "flag.las", bytes);
  EXPECT_EQ(formatOf(dir / "flag.las"), "LAZ");
  EXPECT_THROW(readCloud(dir / "flag.las", quiet()), InputError); // no LASzip VLR says how
}

TEST(LasReader, LyingCountsAreRefusedBeforeAllocating) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  iotest::TempDir dir;
  auto bytes = iotest::readBytes(data("las/1.2-with-color.las"));
  auto patched = bytes;
  uint32_t huge = 0xFFFFFFFFu;
  std::memcpy(patched.data() + 107, &huge, 4);
  iotest::writeBytes(dir / "count.las", patched);
  EXPECT_THROW(readCloud(dir / "count.las", quiet()), InputError);

  auto v14 = iotest::readBytes(data("las/autzen_trim_7.las"));
  uint64_t huge64 = uint64_t(1) << 62;
  std::memcpy(v14.data() + 247, &huge64, 8);
  iotest::writeBytes(dir / "count64.las", v14);
  EXPECT_THROW(readCloud(dir / "count64.las", quiet()), InputError);

  patched = bytes;
  uint16_t shortRecord = 20; // PF3 needs 34
  std::memcpy(patched.data() + 105, &shortRecord, 2);
  iotest::writeBytes(dir / "record.las", patched);
  EXPECT_THROW(readCloud(dir / "record.las", quiet()), InputError);

  patched = bytes;
  double nanScale = NAN;
  std::memcpy(patched.data() + 131, &nanScale, 8);
  iotest::writeBytes(dir / "scale.las", patched);
  EXPECT_THROW(readCloud(dir / "scale.las", quiet()), InputError);

  patched = bytes;
  double hugeScale = 1e305;
  std::memcpy(patched.data() + 131, &hugeScale, 8);
  iotest::writeBytes(dir / "overflow.las", patched);
  EXPECT_THROW(readCloud(dir / "overflow.las", quiet()), InputError);
}

} // namespace
