// PLY reader: the real files in shared/data/ply and synthesized variants (encodings, types, elements).
#include <cmath>

#include "io/io_test_util.h"

using pointrast::InputError;
using pointrast::packRgba;
using pointrast::PointCloud;
using namespace pointrast::io;
using iotest::data;
using iotest::quiet;

namespace {

template <class T> void put(std::vector<uint8_t>& out, T v, bool bigEndian = false) {
  uint8_t b[sizeof(T)];
  std::memcpy(b, &v, sizeof v);
  if (bigEndian) std::reverse(b, b + sizeof(T));
  out.insert(out.end(), b, b + sizeof(T));
}

std::vector<uint8_t> bytesOf(const std::string& s) {
  return std::vector<uint8_t>(s.begin(), s.end());
}

void append(std::vector<uint8_t>& out, const std::vector<uint8_t>& more) {
  out.insert(out.end(), more.begin(), more.end());
}

void expectPoints(const PointCloud& cloud, const std::vector<glm::dvec3>& points, double tolerance = 1e-9) {
  ASSERT_EQ(cloud.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(cloud.world(i)[a], points[i][a], tolerance) << "point " << i << " axis " << a;
    }
}

const std::vector<glm::dvec3> kSimple = {{-1, 0, 0}, {0, 1, 0}, {1, 0, 0}};

TEST(PlyReader, SimpleTextAndBinaryAgree) {
  POINTRAST_REQUIRE_DATA("ply/simple_text.ply");
  PointCloud text = readCloud(data("ply/simple_text.ply"), quiet());
  PointCloud binary = readCloud(data("ply/simple_binary.ply"), quiet());
  expectPoints(text, kSimple);
  expectPoints(binary, kSimple);
  EXPECT_FALSE(text.hasColor());
  EXPECT_EQ(text.bounds.min, glm::dvec3(-1, 0, 0));
  EXPECT_EQ(text.bounds.max, glm::dvec3(1, 1, 0));
  FileInfo info = probeFile(data("ply/simple_binary.ply"));
  EXPECT_STREQ(info.format->name, "PLY");
  EXPECT_EQ(info.formatDetail, "PLY binary_little_endian 1.0");
  EXPECT_EQ(info.pointCount, 3u);
  EXPECT_FALSE(info.boundsFromHeader);
}

TEST(PlyReader, MugBinary) {
  POINTRAST_REQUIRE_DATA("ply/table_scene_mug_stereo_textured.ply");
  PointCloud cloud = readCloud(data("ply/table_scene_mug_stereo_textured.ply"), quiet());
  ASSERT_EQ(cloud.size(), 209280u);
  const double lo[3] = {-0.45643, -0.51074, 0.69001}, hi[3] = {0.71518, 0.17923, 2.59270};
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(cloud.bounds.min[a], lo[a], 6e-6);
    EXPECT_NEAR(cloud.bounds.max[a], hi[a], 6e-6);
  }
  ASSERT_TRUE(cloud.hasColor());
  int cmin = 255, cmax = 0;
  for (uint32_t c : cloud.colors)
    for (int ch = 0; ch < 3; ++ch) {
      cmin = std::min<int>(cmin, iotest::channel(c, ch));
      cmax = std::max<int>(cmax, iotest::channel(c, ch));
    }
  EXPECT_EQ(cmin, 0);
  EXPECT_EQ(cmax, 255);
  FileInfo info = probeFile(data("ply/table_scene_mug_stereo_textured.ply"));
  EXPECT_EQ(info.pointCount, 209280u);
  EXPECT_TRUE(info.hasColor);
  EXPECT_EQ(info.colorBits, 8);
  EXPECT_NEAR(info.bounds.max.z, 2.59270, 6e-6);
}

TEST(PlyReader, Ascii20kMatchesTheBinaryFile) {
  POINTRAST_REQUIRE_DATA("ply/table_scene_mug_stereo_textured.ply");
  PointCloud binary = readCloud(data("ply/table_scene_mug_stereo_textured.ply"), quiet());
  PointCloud ascii = readCloud(data("ply/table_scene_mug_stereo_textured_ascii20k.ply"), quiet());
  ASSERT_EQ(ascii.size(), 20000u);
  const double lo[3] = {-0.39103, -0.51074, 1.85290}, hi[3] = {0.66701, -0.33571, 2.36740};
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(ascii.bounds.min[a], lo[a], 6e-6);
    EXPECT_NEAR(ascii.bounds.max[a], hi[a], 6e-6);
  }
  // The ascii file holds the shortest decimals of the binary file's float32 values. Both were quantized
  // with their own scale/offset (error <= 5e-10 here): back in world coordinates they agree to half a
  // float32 step plus that, and round to the same float32 except where the float spacing is finer than
  // the quantization step (near 0; checked above 0.1).
  for (uint64_t i = 0; i < ascii.size(); ++i) {
    glm::dvec3 a = ascii.world(i), b = binary.world(i);
    for (int k = 0; k < 3; ++k) {
      float f = static_cast<float>(b[k]);
      double halfStep = 0.5 * (std::nextafter(std::fabs(f), INFINITY) - std::fabs(f));
      ASSERT_NEAR(a[k], b[k], halfStep + 1e-9) << "vertex " << i;
      if (std::fabs(b[k]) > 0.1) {
        ASSERT_EQ(static_cast<float>(a[k]), static_cast<float>(b[k])) << "vertex " << i;
      }
    }
    ASSERT_EQ(ascii.colors[i], binary.colors[i]) << "vertex " << i;
  }
}

// A PLY file with the given vertex properties (type name pairs) and rows of values.
struct PlyBuilder {
  std::string encoding = "binary_little_endian";
  std::string preamble;                                        // extra header lines before the vertex element
  std::vector<uint8_t> preData;                                // data of elements before vertex
  std::vector<std::pair<std::string, std::string>> properties; // (type, name)
  std::vector<std::vector<double>> rows;
  std::string newline = "\n";
  int64_t claimedCount = -1;

  std::vector<uint8_t> build() const {
    std::string h =
        "ply" + newline + "format " + encoding + " 1.0" + newline + "comment made by a test" + newline;
    h += preamble;
    h += "element vertex " + std::to_string(claimedCount >= 0 ? uint64_t(claimedCount) : rows.size()) +
         newline;
    for (const auto& [type, name] : properties)
      h += "property " + type + " " + name + newline;
    h += "element face 0" + newline + "property list uchar int vertex_indices" + newline;
    h += "end_header" + newline;
    std::vector<uint8_t> out = bytesOf(h);
    append(out, preData);
    bool be = encoding == "binary_big_endian";
    for (const auto& row : rows) {
      if (encoding == "ascii") {
        std::string line;
        for (double v : row) {
          char buf[64];
          std::snprintf(buf, sizeof buf, "%.17g ", v);
          line += buf;
        }
        append(out, bytesOf(line + newline));
        continue;
      }
      for (size_t j = 0; j < row.size(); ++j) {
        const std::string& t = properties[j].first;
        double v = row[j];
        if (t == "char" || t == "int8")
          put<int8_t>(out, static_cast<int8_t>(v));
        else if (t == "uchar" || t == "uint8")
          put<uint8_t>(out, static_cast<uint8_t>(v));
        else if (t == "short" || t == "int16")
          put<int16_t>(out, static_cast<int16_t>(v), be);
        else if (t == "ushort" || t == "uint16")
          put<uint16_t>(out, static_cast<uint16_t>(v), be);
        else if (t == "int" || t == "int32")
          put<int32_t>(out, static_cast<int32_t>(v), be);
        else if (t == "uint" || t == "uint32")
          put<uint32_t>(out, static_cast<uint32_t>(v), be);
        else if (t == "float" || t == "float32")
          put<float>(out, static_cast<float>(v), be);
        else
          put<double>(out, v, be);
      }
    }
    return out;
  }
};

PointCloud readBuilt(const PlyBuilder& b, const std::string& name = "t.ply") {
  iotest::TempDir dir;
  iotest::writeBytes(dir / name, b.build());
  return readCloud(dir / name, quiet());
}

std::string refusal(const PlyBuilder& b) {
  iotest::TempDir dir;
  iotest::writeBytes(dir / "t.ply", b.build());
  std::string message;
  EXPECT_EQ(iotest::readOrRefuse(dir / "t.ply", &message), iotest::Outcome::Refused);
  return message;
}

PlyBuilder xyzRgb(const std::string& coordType, const std::string& colorType) {
  PlyBuilder b;
  b.properties = {{coordType, "x"}, {coordType, "y"}, {coordType, "z"}};
  if (!colorType.empty())
    b.properties.insert(b.properties.end(), {{colorType, "red"}, {colorType, "green"}, {colorType, "blue"}});
  return b;
}

TEST(PlyReader, AllEncodingsAndCoordinateTypes) {
  const std::vector<std::vector<double>> rows = {{1.5, -2.25, 3}, {-4, 5.5, 6.75}, {7, 8, -9.5}};
  for (const char* encoding : {"binary_little_endian", "binary_big_endian", "ascii"})
    for (const char* type : {"float", "double", "float32", "float64"}) {
      SCOPED_TRACE(std::string(encoding) + " " + type);
      PlyBuilder b = xyzRgb(type, "");
      b.encoding = encoding;
      b.rows = rows;
      expectPoints(readBuilt(b), {{1.5, -2.25, 3}, {-4, 5.5, 6.75}, {7, 8, -9.5}});
    }
  for (const char* encoding : {"binary_little_endian", "binary_big_endian", "ascii"})
    for (const char* type : {"char", "uchar", "short", "ushort", "int", "uint", "int8", "uint8", "int16",
                             "uint16", "int32", "uint32"}) {
      SCOPED_TRACE(std::string(encoding) + " " + type);
      PlyBuilder b = xyzRgb(type, "");
      b.encoding = encoding;
      b.rows = {{1, 2, 3}, {100, 50, 0}, {7, 127, 9}};
      expectPoints(readBuilt(b), {{1, 2, 3}, {100, 50, 0}, {7, 127, 9}});
    }
  PlyBuilder big = xyzRgb("int", "");
  big.rows = {{-2000000000, 0, 5}, {2000000000, 1, 5}};
  expectPoints(readBuilt(big), {{-2000000000, 0, 5}, {2000000000, 1, 5}}, 2.0); // 4e9 span: scale 1
}

TEST(PlyReader, ColorTypes) {
  PlyBuilder u8 = xyzRgb("float", "uchar");
  u8.rows = {{0, 0, 0, 255, 12, 234}};
  EXPECT_EQ(readBuilt(u8).colors.at(0), packRgba(255, 12, 234));

  PlyBuilder u16 = xyzRgb("float", "ushort");
  u16.rows = {{0, 0, 0, 65535, 3072, 256}, {1, 1, 1, 0, 255, 128}};
  PointCloud c16 = readBuilt(u16);
  EXPECT_EQ(c16.colors.at(0), packRgba(255, 12, 1));
  EXPECT_EQ(c16.colors.at(1), packRgba(0, 0, 0));
  PlyBuilder u16small = xyzRgb("float", "ushort"); // 8-bit values in 16-bit fields
  u16small.rows = {{0, 0, 0, 200, 12, 0}};
  EXPECT_EQ(readBuilt(u16small).colors.at(0), packRgba(200, 12, 0));

  for (const char* encoding : {"binary_big_endian", "ascii"}) {
    PlyBuilder f = xyzRgb("double", "float");
    f.encoding = encoding;
    f.rows = {{0, 0, 0, 1.0, 0.5, 0.0}, {1, 0, 0, 0.2, -0.5, 2e-3}};
    PointCloud cf = readBuilt(f);
    EXPECT_EQ(cf.colors.at(0), packRgba(255, 128, 0)) << encoding;
    EXPECT_EQ(cf.colors.at(1), packRgba(51, 0, 1)) << encoding;
  }
  PlyBuilder f255 = xyzRgb("float", "float"); // float colors written 0..255
  f255.rows = {{0, 0, 0, 255, 12.2, 0.6}};
  EXPECT_EQ(readBuilt(f255).colors.at(0), packRgba(255, 12, 1));

  FileInfo info;
  {
    iotest::TempDir dir;
    iotest::writeBytes(dir / "c.ply", u16.build());
    info = probeFile(dir / "c.ply");
  }
  EXPECT_TRUE(info.hasColor);
  EXPECT_EQ(info.colorBits, 16);
}

TEST(PlyReader, ElementsBeforeVertexAreSkipped) {
  for (const char* encoding : {"binary_little_endian", "binary_big_endian", "ascii"}) {
    SCOPED_TRACE(encoding);
    bool be = std::string(encoding) == "binary_big_endian";
    PlyBuilder b = xyzRgb("float", "uchar");
    b.encoding = encoding;
    b.properties.insert(b.properties.begin() + 1, {"double", "confidence"}); // skipped property
    b.rows = {{1, 0.5, 2, 3, 10, 20, 30}, {4, 0.25, 5, 6, 40, 50, 60}};
    // A fixed-size element and an element with lists, both before the vertex element.
    b.preamble = "element camera 2\nproperty float fx\nproperty short id\n"
                 "element range_grid 3\nproperty list uchar int idx\nproperty uchar flag\n";
    if (b.encoding == "ascii") {
      b.preData = bytesOf("1.5 7\n2.5 8\n2 10 11 1\n0 0\n3 1 2 3 1\n");
    } else {
      for (int i = 0; i < 2; ++i) {
        put<float>(b.preData, 1.5f, be);
        put<int16_t>(b.preData, 7, be);
      }
      for (uint8_t n : {2, 0, 3}) {
        put<uint8_t>(b.preData, n);
        for (int k = 0; k < n; ++k)
          put<int32_t>(b.preData, k, be);
        put<uint8_t>(b.preData, 1);
      }
    }
    PointCloud cloud = readBuilt(b);
    expectPoints(cloud, {{1, 2, 3}, {4, 5, 6}});
    EXPECT_EQ(cloud.colors.at(1), packRgba(40, 50, 60));
  }
}

TEST(PlyReader, ListPropertyInsideVertex) {
  for (const char* encoding : {"binary_little_endian", "ascii"}) {
    SCOPED_TRACE(encoding);
    std::string h = std::string("ply\nformat ") + encoding +
                    " 1.0\nelement vertex 2\nproperty float x\n"
                    "property list uchar float normals\nproperty float y\nproperty float z\nend_header\n";
    std::vector<uint8_t> file = bytesOf(h);
    if (std::string(encoding) == "ascii") {
      append(file, bytesOf("1 3 0.1 0.2 0.3 2 3\n4 0 5 6\n"));
    } else {
      put<float>(file, 1);
      put<uint8_t>(file, 3);
      for (float v : {0.1f, 0.2f, 0.3f})
        put<float>(file, v);
      put<float>(file, 2);
      put<float>(file, 3);
      put<float>(file, 4);
      put<uint8_t>(file, 0);
      put<float>(file, 5);
      put<float>(file, 6);
    }
    iotest::TempDir dir;
    iotest::writeBytes(dir / "l.ply", file);
    expectPoints(readCloud(dir / "l.ply", quiet()), {{1, 2, 3}, {4, 5, 6}});
  }
}

TEST(PlyReader, TolerantHeader) {
  PlyBuilder b = xyzRgb("float", "");
  b.newline = "\r\n";
  b.rows = {{1, 2, 3}};
  expectPoints(readBuilt(b), {{1, 2, 3}});
  b.encoding = "ascii";
  expectPoints(readBuilt(b), {{1, 2, 3}});
  iotest::TempDir dir;
  iotest::writeText(dir / "s.ply",
                    "ply  \nformat ascii 1.0 \nobj_info x\ncomment\n\nelement vertex 1 \n"
                    "property   float x\nproperty float y\nproperty float z\nend_header  \n1 2 3");
  expectPoints(readCloud(dir / "s.ply", quiet()), {{1, 2, 3}});
}

TEST(PlyReader, EmptyVertexElementIsAnEmptyCloud) {
  PlyBuilder b = xyzRgb("float", "uchar");
  PointCloud cloud = readBuilt(b);
  EXPECT_EQ(cloud.size(), 0u);
  EXPECT_TRUE(cloud.bounds.empty());
}

TEST(PlyReader, BadFilesAreRefused) {
  PlyBuilder more = xyzRgb("float", "uchar");
  more.rows = {{1, 2, 3, 4, 5, 6}};
  more.claimedCount = 2;
  EXPECT_NE(refusal(more).find("header claims 2 vertices of 15 bytes"), std::string::npos) << refusal(more);
  more.claimedCount = 1000000000000000;
  EXPECT_NE(refusal(more).find("1000000000000000 vertices"), std::string::npos);
  more.encoding = "ascii";
  more.claimedCount = 2;
  EXPECT_NE(refusal(more).find("ends in vertex 2 of 2"), std::string::npos) << refusal(more);
  more.claimedCount = 1000000000000000;
  refusal(more);

  PlyBuilder noZ;
  noZ.properties = {{"float", "x"}, {"float", "y"}};
  EXPECT_NE(refusal(noZ).find("lacks an x, y or z"), std::string::npos);
  PlyBuilder badType = xyzRgb("float128", "");
  EXPECT_NE(refusal(badType).find("unknown property type 'float128'"), std::string::npos) << refusal(badType);
  PlyBuilder badEncoding = xyzRgb("float", "");
  badEncoding.encoding = "binary_middle_endian";
  refusal(badEncoding);
  PlyBuilder badNumber = xyzRgb("float", "");
  badNumber.encoding = "ascii";
  badNumber.rows = {{1, 2, 3}};
  auto file = badNumber.build();
  file[file.size() - 3] = 'q';
  {
    iotest::TempDir dir;
    iotest::writeBytes(dir / "n.ply", file);
    std::string message;
    EXPECT_EQ(iotest::readOrRefuse(dir / "n.ply", &message), iotest::Outcome::Refused);
    EXPECT_NE(message.find("line 11"), std::string::npos) << message;
  }
  // Huge element before vertex (fixed size) and a huge list count.
  PlyBuilder pre = xyzRgb("float", "");
  pre.preamble = "element junk 99999999999999\nproperty double a\n";
  EXPECT_NE(refusal(pre).find("junk"), std::string::npos) << refusal(pre);
  pre.preamble = "element junk 1\nproperty list uint double a\n";
  put<uint32_t>(pre.preData, 0xFFFFFFFFu);
  refusal(pre);
  iotest::TempDir dir;
  iotest::writeText(dir / "nohead.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n");
  EXPECT_NE(
      [&] {
        std::string m;
        iotest::readOrRefuse(dir / "nohead.ply", &m);
        return m;
      }()
          .find("end_header"),
      std::string::npos);
}

TEST(PlyReader, NonFiniteVerticesAreDroppedAndCounted) {
  for (const char* encoding : {"binary_little_endian", "ascii"}) {
    PlyBuilder b = xyzRgb("float", "uchar");
    b.encoding = encoding;
    b.rows = {
        {1, 2, 3, 10, 10, 10}, {NAN, 0, 0, 20, 20, 20}, {4, INFINITY, 6, 30, 30, 30}, {7, 8, 9, 40, 40, 40}};
    iotest::TempDir dir;
    iotest::writeBytes(dir / "nan.ply", b.build());
    PointCloud cloud = readCloud(dir / "nan.ply", quiet());
    expectPoints(cloud, {{1, 2, 3}, {7, 8, 9}});
    EXPECT_EQ(cloud.colors, (std::vector<uint32_t>{packRgba(10, 10, 10), packRgba(40, 40, 40)}));
    FileInfo info = probeFile(dir / "nan.ply");
    bool listed = false;
    for (const auto& [key, value] : info.extra)
      listed = listed || (key.find("dropped") != std::string::npos && value.find('2') == 0);
    EXPECT_TRUE(listed) << encoding;
  }
}

// Quantization to int32 + scale/offset keeps every point within 1e-7 of the extent (in practice
// ~2e-9), including large offsets and a flat axis.
TEST(PlyReader, QuantizationErrorIsTiny) {
  iotest::Lcg rng(7);
  PlyBuilder b = xyzRgb("double", "");
  for (int i = 0; i < 2000; ++i)
    b.rows.push_back({500000.0 + 1234.5678 * rng.uniform(), -4.0e6 + 0.001 * rng.uniform(), 42.0});
  PointCloud cloud = readBuilt(b);
  ASSERT_EQ(cloud.size(), 2000u);
  glm::dvec3 extent = cloud.bounds.size();
  EXPECT_EQ(extent.z, 0.0);
  for (size_t i = 0; i < b.rows.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      double err = std::fabs(cloud.world(i)[a] - b.rows[i][static_cast<size_t>(a)]);
      ASSERT_LE(err, std::max(1e-7 * extent[a], 1e-12)) << "point " << i << " axis " << a;
    }
  // Power-of-ten steps.
  EXPECT_EQ(cloud.scale.x, 1e-6);
  EXPECT_EQ(cloud.scale.y, 1e-12);
}

} // namespace
