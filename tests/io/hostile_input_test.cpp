// Hostile input: every prefix of a file, flipped header bytes, random bytes, empty files. Each read
// must either succeed or throw InputError: no crash, no other exception, no huge allocation (run under
// AddressSanitizer, see environment_test.cpp).
#include "io/io_test_util.h"
#include "io/las/laz_compose.h"
#include "io/writer.h"

using pointrast::InputError;
using pointrast::PointCloud;
using namespace pointrast::io;
using iotest::data;
using iotest::Outcome;
using iotest::quiet;
using iotest::readOrRefuse;

namespace {

// Reads every prefix [0, full) at step 1 up to denseEnd, then at stride; returns the refusal count.
size_t sweepPrefixes(const std::vector<uint8_t>& bytes, const std::string& name, size_t denseEnd,
                     size_t stride, bool prefixesMustFail, bool wholeMustRead = true) {
  iotest::TempDir dir;
  auto path = dir / name;
  size_t refused = 0;
  for (size_t len = 0; len < bytes.size(); len += len < denseEnd ? 1 : stride) {
    iotest::writeBytes(path, bytes.data(), len);
    Outcome outcome = readOrRefuse(path);
    refused += outcome == Outcome::Refused;
    if (prefixesMustFail) {
      EXPECT_EQ(outcome, Outcome::Refused) << name << " prefix " << len;
    }
    if (::testing::Test::HasFailure()) break;
  }
  iotest::writeBytes(path, bytes);
  EXPECT_EQ(readOrRefuse(path), wholeMustRead ? Outcome::Read : Outcome::Refused) << name << " in full";
  return refused;
}

// Sets each byte in [begin, end) to each of values (and to itself xor a few bits) and reads the result.
void flipBytes(const std::vector<uint8_t>& bytes, const std::string& name, size_t begin, size_t end,
               const std::vector<uint8_t>& values) {
  iotest::TempDir dir;
  auto path = dir / name;
  std::vector<uint8_t> copy = bytes;
  for (size_t i = begin; i < std::min(end, bytes.size()); ++i) {
    std::vector<uint8_t> tries = values;
    for (uint8_t bit : {0x01, 0x10, 0x80})
      tries.push_back(bytes[i] ^ bit);
    for (uint8_t v : tries) {
      copy[i] = v;
      iotest::writeBytes(path, copy);
      readOrRefuse(path);
    }
    copy[i] = bytes[i];
    if (::testing::Test::HasFailure()) return;
  }
}

std::vector<uint8_t> smallLas(LasFlavor flavor, int points) {
  PointCloud cloud;
  cloud.scale = glm::dvec3(0.01);
  cloud.offset = glm::dvec3(1000, 2000, 3000);
  for (int i = 0; i < points; ++i) {
    cloud.positions.insert(cloud.positions.end(), {i * 7, -i * 3, i});
    cloud.colors.push_back(pointrast::packRgba(i, 2 * i, 3 * i));
    cloud.intensity.push_back(static_cast<uint16_t>(i));
    cloud.classification.push_back(2);
    cloud.returnNumber.push_back(1);
  }
  iotest::TempDir dir;
  writeLas(dir / "s.las", cloud, flavor);
  return iotest::readBytes(dir / "s.las");
}

TEST(HostileInput, LasPrefixes) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  auto real = iotest::readBytes(data("las/1.2-with-color.las"));
  sweepPrefixes(real, "t.las", 229 + 3 * 34, 97, true);
  auto pf7 = smallLas(LasFlavor::Las14Pf7, 40);
  sweepPrefixes(pf7, "t.las", pf7.size(), 1, true);
  auto padded = iotest::readBytes(data("las/permutations/1.0_0.las")); // VLRs and pad bytes
  sweepPrefixes(padded, "t.las", padded.size(), 1, true);
}

TEST(HostileInput, LasHeaderFlips) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  const std::vector<uint8_t> values = {0x00, 0xFF, 0x7F, 0x01};
  auto real = iotest::readBytes(data("las/1.2-with-color.las"));
  flipBytes(real, "f.las", 0, 229, values);
  auto pf7 = smallLas(LasFlavor::Las14Pf7, 20);
  flipBytes(pf7, "f.las", 0, 375, values);
  auto vlrs = iotest::readBytes(data("las/permutations/1.2_3.las")); // header and the VLR chain
  flipBytes(vlrs, "f.las", 90, 400, values);
}

std::vector<uint8_t> asciiMug(int vertices) {
  // The ascii20k file's header with the count cut to `vertices`, and its first `vertices` lines.
  auto bytes = iotest::readBytes(data("ply/table_scene_mug_stereo_textured_ascii20k.ply"));
  std::string text(bytes.begin(), bytes.end());
  size_t headerEnd = text.find("end_header\n") + 11;
  size_t end = headerEnd;
  for (int i = 0; i < vertices; ++i)
    end = text.find('\n', end) + 1;
  std::string header = text.substr(0, headerEnd);
  size_t at = header.find("element vertex 20000");
  header.replace(at, 20, "element vertex " + std::to_string(vertices));
  std::string out = header + text.substr(headerEnd, end - headerEnd);
  return std::vector<uint8_t>(out.begin(), out.end());
}

std::vector<uint8_t> binaryPlyWithElements() {
  std::string h =
      "ply\nformat binary_little_endian 1.0\ncomment x\nelement cam 2\nproperty float f\n"
      "element grid 3\nproperty list uchar int idx\nelement vertex 20\nproperty double x\n"
      "property float y\nproperty short z\nproperty list uchar float n\nproperty uchar red\n"
      "property uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int v\nend_header\n";
  std::vector<uint8_t> out(h.begin(), h.end());
  auto put = [&](const void* p, size_t n) {
    out.insert(out.end(), static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
  };
  float f = 1.5f;
  put(&f, 4);
  put(&f, 4);
  for (uint8_t n : {1, 0, 2}) {
    put(&n, 1);
    for (int32_t k = 0; k < n; ++k)
      put(&k, 4);
  }
  for (int i = 0; i < 20; ++i) {
    double x = i * 0.5;
    float y = -i * 0.25f;
    int16_t z = static_cast<int16_t>(i);
    uint8_t n = static_cast<uint8_t>(i % 3);
    put(&x, 8);
    put(&y, 4);
    put(&z, 2);
    put(&n, 1);
    for (int k = 0; k < n; ++k)
      put(&y, 4);
    uint8_t rgb[3] = {static_cast<uint8_t>(i), 100, 200};
    put(rgb, 3);
  }
  uint8_t three = 3;
  put(&three, 1);
  for (int32_t k = 0; k < 3; ++k)
    put(&k, 4);
  return out;
}

TEST(HostileInput, PlyPrefixes) {
  POINTRAST_REQUIRE_DATA("ply/simple_binary.ply");
  auto simple = iotest::readBytes(data("ply/simple_binary.ply"));
  sweepPrefixes(simple, "t.ply", simple.size(), 1, true);
  auto withElements = binaryPlyWithElements();
  ASSERT_EQ(readCloud(
                [&] {
                  static iotest::TempDir dir;
                  iotest::writeBytes(dir / "e.ply", withElements);
                  return dir / "e.ply";
                }(),
                quiet())
                .size(),
            20u);
  // The face element after the vertices is never read, so only prefixes that cut the vertices fail.
  size_t refused = sweepPrefixes(withElements, "t.ply", withElements.size(), 1, false);
  EXPECT_GE(refused, withElements.size() - 13);
  auto text = iotest::readBytes(data("ply/simple_text.ply"));
  sweepPrefixes(text, "t.ply", text.size(), 1, false);
  auto mug = asciiMug(150);
  sweepPrefixes(mug, "t.ply", mug.size(), 1, false);
  auto mugBinary = iotest::readBytes(data("ply/table_scene_mug_stereo_textured.ply"));
  mugBinary.resize(4000);
  sweepPrefixes(mugBinary, "t.ply", 0, 1, true, false); // claims 209,280 vertices: every prefix fails
}

TEST(HostileInput, LazPrefixes) {
  POINTRAST_REQUIRE_DATA("laz/simple.laz");
  // A prefix loses the chunk table (written last) or part of it. Only the table's trailing zero padding
  // may go missing unnoticed: the decoder reads zeros there anyway, and decodes the same points.
  auto simple = iotest::readBytes(data("laz/simple.laz"));
  size_t refused = sweepPrefixes(simple, "t.laz", 400, 41, false);
  EXPECT_GE(refused, (simple.size() - 400) / 41 + 400 - 1);
  // Layered: dense through the header, VLRs, first raw point and layer table, then every 13th.
  auto layered = composeLaz(data("laz/lone-star.copc.laz"), {0, 9}); // 212 + 318 points, 4.5 KB
  refused = sweepPrefixes(layered, "t.laz", 1200, 13, false);
  EXPECT_GE(refused, (layered.size() - 1200) / 13 + 1200 - 1);
}

TEST(HostileInput, PlyHeaderFlips) {
  POINTRAST_REQUIRE_DATA("ply/simple_binary.ply");
  const std::vector<uint8_t> values = {'0', '9', ' ', '\n', '\r', 'x', 0x00, 0xFF};
  auto simple = iotest::readBytes(data("ply/simple_binary.ply"));
  flipBytes(simple, "f.ply", 0, 208, values);
  auto withElements = binaryPlyWithElements();
  flipBytes(withElements, "f.ply", 0, withElements.size(), values);
  auto text = iotest::readBytes(data("ply/simple_text.ply"));
  flipBytes(text, "f.ply", 0, text.size(), values);
}

TEST(HostileInput, XyzPrefixesAndFlips) {
  POINTRAST_REQUIRE_DATA("xyz/autzen.pts");
  auto pts = iotest::readBytes(data("xyz/autzen.pts"));
  sweepPrefixes(pts, "t.pts", pts.size(), 1, false);
  flipBytes(pts, "f.pts", 0, pts.size(), {'0', ' ', '\n', ',', '.', '-', 'e', 'x', 0x00, 0xFF});
  auto dem = iotest::readBytes(data("xyz/data.xyz"));
  sweepPrefixes(dem, "t.xyz", 400, 7, false);
}

TEST(HostileInput, EmptyAndMissingFiles) {
  iotest::TempDir dir;
  for (const char* name : {"empty.las", "empty.ply", "empty.xyz", "empty.laz", "empty"}) {
    iotest::writeBytes(dir / name, nullptr, 0);
    std::string message;
    EXPECT_EQ(readOrRefuse(dir / name, &message), Outcome::Refused) << name;
    EXPECT_NE(message.find(name), std::string::npos) << message;
    EXPECT_THROW(probeFile(dir / name), InputError) << name;
  }
  EXPECT_THROW(readCloud(dir / "missing.las", quiet()), InputError);
  EXPECT_THROW(probeFile(dir / "missing.las"), InputError);
  EXPECT_THROW(detectFormat(dir / "missing.las"), InputError);
  EXPECT_THROW(readCloud(dir.path(), quiet()), InputError); // a directory
}

TEST(HostileInput, RandomBytes) {
  iotest::TempDir dir;
  iotest::Lcg rng(1234);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<uint8_t> bytes(1 + rng.next() % 3000);
    for (auto& b : bytes)
      b = static_cast<uint8_t>(rng.next());
    // Magic bytes in front make the format parsers (not just detection) see the garbage.
    const char* magic[] = {"", "LASF", "ply\n", "ply\nformat binary_little_endian 1.0\n", "MMPLD"};
    const char* names[] = {"r.bin", "r.las", "r.ply", "r.xyz", "r.csv"};
    std::string m = magic[trial % 5];
    std::copy(m.begin(), m.end(), bytes.begin());
    if (bytes.size() < m.size())
      bytes.insert(bytes.end(), m.begin() + static_cast<ptrdiff_t>(bytes.size()), m.end());
    auto path = dir / names[(trial / 5) % 5];
    iotest::writeBytes(path, bytes);
    EXPECT_EQ(readOrRefuse(path), Outcome::Refused) << "trial " << trial;
    EXPECT_THROW(probeFile(path), InputError) << "trial " << trial;
  }
}

} // namespace
