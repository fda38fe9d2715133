// MMPLD: the 17 reference files of the VISUS mmpld library, files built byte by byte here for the
// versions and types those files lack (1.0, 1.1 with cluster data, 1.3 with and without the timestamp,
// SHORT_XYZ, UINT8_RGB, several frames), write -> read round trips, chunked decoding, and hostile
// input. Expected values come from the file layout (particles_io.h) and the bytes, never from the reader.
#include <cmath>
#include <limits>

#include "io/formats.h"
#include "io/io_test_util.h"
#include "io/particles/particles_io.h"

using pointrast::Bounds;
using pointrast::InputError;
using pointrast::packRgba;
using pointrast::particleRamp;
using pointrast::ParticleSet;
using namespace pointrast::io;
using iotest::data;
using iotest::formatOf;

namespace {

MmpldReadOptions quietFrame(uint32_t frame = 0) {
  MmpldReadOptions o;
  o.frame = frame;
  o.progress = false;
  return o;
}

// ---- a byte-level MMPLD builder, independent of the writer under test ------------------------------

template <class T> void put(std::vector<uint8_t>& out, T v) {
  const auto* p = reinterpret_cast<const uint8_t*>(&v);
  out.insert(out.end(), p, p + sizeof v);
}

struct ListSpec {
  uint8_t vertex = 1, color = 0;
  float radius = 0.1f;         // written for vertex types 1, 3, 4
  uint32_t rgba = 0xFF00FFFFu; // written for color type 0 (bytes R, G, B, A = FF, FF, 00, FF)
  float range[2] = {0, 1};     // written for color types 3, 7
  uint64_t count = 0;          // as stated
  std::vector<uint8_t> particles;
  float box[6] = {-1, -1, -1, 1, 1, 1}; // written for 1.3
  std::vector<uint8_t> clusters = {};   // 1.1: the cluster payload
};

struct FrameSpec {
  float timestamp = 0.5f;
  bool timestamp13 = true; // false: a 1.3 frame as older MegaMol wrote it
  std::vector<ListSpec> lists;
};

std::vector<uint8_t> frameBytes(uint16_t version, const FrameSpec& f) {
  std::vector<uint8_t> out;
  if (version >= 102 && (version != 103 || f.timestamp13)) put(out, f.timestamp);
  put<uint32_t>(out, uint32_t(f.lists.size()));
  for (const ListSpec& l : f.lists) {
    put(out, l.vertex);
    put(out, l.color);
    if (l.vertex == 1 || l.vertex == 3 || l.vertex == 4) put(out, l.radius);
    if (l.color == 0) put(out, l.rgba);
    if (l.color == 3 || l.color == 7) put(out, l.range[0]), put(out, l.range[1]);
    put(out, l.count);
    if (version == 103)
      for (float v : l.box)
        put(out, v);
    out.insert(out.end(), l.particles.begin(), l.particles.end());
    if (version == 101) {
      put<uint32_t>(out, 3);
      put<uint64_t>(out, l.clusters.size());
      out.insert(out.end(), l.clusters.begin(), l.clusters.end());
    }
  }
  return out;
}

std::vector<uint8_t> buildMmpld(uint16_t version, const std::vector<FrameSpec>& frames) {
  std::vector<uint8_t> out = {'M', 'M', 'P', 'L', 'D', 0};
  put(out, version);
  put<uint32_t>(out, uint32_t(frames.size()));
  for (float v : {-3.f, -3.f, -3.f, 3.f, 3.f, 3.f, -4.f, -4.f, -4.f, 4.f, 4.f, 4.f})
    put(out, v);
  std::vector<std::vector<uint8_t>> bodies;
  for (const FrameSpec& f : frames)
    bodies.push_back(frameBytes(version, f));
  uint64_t at = out.size() + 8 * (frames.size() + 1);
  for (const auto& b : bodies) {
    put(out, at);
    at += b.size();
  }
  put(out, at);
  for (const auto& b : bodies)
    out.insert(out.end(), b.begin(), b.end());
  return out;
}

// Particles for ListSpec::particles.
struct Particles {
  std::vector<uint8_t> bytes;
  template <class... T> Particles& add(T... values) {
    (put(bytes, values), ...);
    return *this;
  }
};

ListSpec floatList(std::initializer_list<glm::vec3> points, uint32_t rgba = 0xFF00FFFFu,
                   float radius = 0.1f) {
  ListSpec l;
  l.vertex = 1;
  l.rgba = rgba;
  l.radius = radius;
  Particles p;
  for (const glm::vec3& v : points)
    p.add(v.x, v.y, v.z);
  l.count = points.size();
  l.particles = p.bytes;
  return l;
}

// ---- the reference files ------------------------------------------------------------------------------

// The files of UniStuttgart-VISUS/mmpld test/ are named test_<vertex>_<precision>_<color>_<colorprecision>
// and all hold MMPLD 1.2, one frame at timestamp 1.23, a header box of -2..2 and a clip box of -2.1..2.1
// (-2.5..2.5 with radii). Their first list holds four particles at the origin and the three unit
// points; with per-particle radii those are 0.5, 0.2, 0.3, 0.4, else the global radius is 0.1. Colors:
// white, red, green, blue; intensities 255, 64, 128, 192 over the range 0..255; no color: yellow.
// The double files add three FLOAT_XYZ lists of five particles walking from a corner of the box toward
// the center along x, y and z in steps of 0.2, colored red, green and blue by their global color.
struct Reference {
  const char* name;
  MmpldVertex vertex;
  MmpldColor color;
};

const Reference kReferences[] = {
    {"test_xyz_double_int_double", MmpldVertex::DoubleXyz, MmpldColor::DoubleI},
    {"test_xyz_double_int_float", MmpldVertex::DoubleXyz, MmpldColor::FloatI},
    {"test_xyz_double_none", MmpldVertex::DoubleXyz, MmpldColor::None},
    {"test_xyz_double_rgb_float", MmpldVertex::DoubleXyz, MmpldColor::FloatRgb},
    {"test_xyz_double_rgba_byte", MmpldVertex::DoubleXyz, MmpldColor::Uint8Rgba},
    {"test_xyz_double_rgba_float", MmpldVertex::DoubleXyz, MmpldColor::FloatRgba},
    {"test_xyz_double_rgba_short", MmpldVertex::DoubleXyz, MmpldColor::Uint16Rgba},
    {"test_xyz_float_int_float", MmpldVertex::FloatXyz, MmpldColor::FloatI},
    {"test_xyz_float_none", MmpldVertex::FloatXyz, MmpldColor::None},
    {"test_xyz_float_rgb_float", MmpldVertex::FloatXyz, MmpldColor::FloatRgb},
    {"test_xyz_float_rgba_byte", MmpldVertex::FloatXyz, MmpldColor::Uint8Rgba},
    {"test_xyz_float_rgba_float", MmpldVertex::FloatXyz, MmpldColor::FloatRgba},
    {"test_xyzr_float_int_float", MmpldVertex::FloatXyzr, MmpldColor::FloatI},
    {"test_xyzr_float_none", MmpldVertex::FloatXyzr, MmpldColor::None},
    {"test_xyzr_float_rgb_float", MmpldVertex::FloatXyzr, MmpldColor::FloatRgb},
    {"test_xyzr_float_rgba_byte", MmpldVertex::FloatXyzr, MmpldColor::Uint8Rgba},
    {"test_xyzr_float_rgba_float", MmpldVertex::FloatXyzr, MmpldColor::FloatRgba},
};

std::filesystem::path referencePath(const Reference& r) {
  return data(std::string("mmpld/") + r.name + ".mmpld");
}

struct Expected {
  glm::dvec3 position;
  float radius;
  uint32_t color;
};

std::vector<Expected> expectedParticles(const Reference& r) {
  const glm::dvec3 unit[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const float radii[4] = {0.5f, 0.2f, 0.3f, 0.4f};
  const uint32_t rgb[4] = {packRgba(255, 255, 255), packRgba(255, 0, 0), packRgba(0, 255, 0),
                           packRgba(0, 0, 255)};
  const double intensity[4] = {255, 64, 128, 192};
  std::vector<Expected> out;
  for (int i = 0; i < 4; ++i) {
    Expected e{unit[i], r.vertex == MmpldVertex::FloatXyzr ? radii[i] : 0.1f, rgb[i]};
    if (r.color == MmpldColor::None) e.color = packRgba(255, 255, 0);
    if (r.color == MmpldColor::FloatI || r.color == MmpldColor::DoubleI)
      e.color = particleRamp(intensity[i] / 255);
    out.push_back(e);
  }
  if (r.vertex == MmpldVertex::DoubleXyz)
    for (int axis = 0; axis < 3; ++axis)
      for (int k = 0; k < 5; ++k) {
        glm::dvec3 p(-2);
        p[axis] = double(2.0f - 0.2f * float(k)); // as float, the way the file stores it
        uint32_t c = packRgba(axis == 0 ? 255 : 0, axis == 1 ? 255 : 0, axis == 2 ? 255 : 0);
        out.push_back({p, 0.1f, c});
      }
  return out;
}

class ReferenceFile : public ::testing::TestWithParam<Reference> {};

TEST_P(ReferenceFile, HeadersAreAsStated) {
  POINTRAST_REQUIRE_DATA();
  const Reference& r = GetParam();
  const MmpldInfo info = probeMmpld(referencePath(r));
  EXPECT_EQ(formatOf(referencePath(r)), "MMPLD");
  EXPECT_EQ(info.version, 102);
  EXPECT_EQ(info.frames, 1u);
  EXPECT_TRUE(info.hasTimestamp);
  EXPECT_FALSE(info.timestampMissing);
  EXPECT_EQ(info.timestamp, 1.23f);
  EXPECT_EQ(info.bbox.min, glm::dvec3(-2));
  EXPECT_EQ(info.bbox.max, glm::dvec3(2));
  const float clip = r.vertex == MmpldVertex::FloatXyzr ? 2.5f : 2.1f;
  EXPECT_EQ(info.clipBox.max, glm::dvec3(clip));
  EXPECT_EQ(info.clipBox.min, glm::dvec3(-clip));
  const bool isDouble = r.vertex == MmpldVertex::DoubleXyz;
  ASSERT_EQ(info.lists.size(), isDouble ? 4u : 1u);
  EXPECT_EQ(info.lists[0].vertex, r.vertex);
  EXPECT_EQ(info.lists[0].color, r.color);
  EXPECT_EQ(info.lists[0].count, 4u);
  EXPECT_FALSE(info.lists[0].hasBounds); // 1.3 only
  if (r.color == MmpldColor::FloatI || r.color == MmpldColor::DoubleI) {
    EXPECT_EQ(info.lists[0].intensityMin, 0.0f);
    EXPECT_EQ(info.lists[0].intensityMax, 255.0f);
  }
  for (size_t l = 1; l < info.lists.size(); ++l) {
    EXPECT_EQ(info.lists[l].vertex, MmpldVertex::FloatXyz);
    EXPECT_EQ(info.lists[l].color, MmpldColor::None);
    EXPECT_EQ(info.lists[l].count, 5u);
    EXPECT_EQ(info.lists[l].globalRadius, 0.1f);
  }
  EXPECT_EQ(info.particles(), isDouble ? 19u : 4u);
}

TEST_P(ReferenceFile, ParticlesRadiiAndColors) {
  POINTRAST_REQUIRE_DATA();
  const Reference& r = GetParam();
  const ParticleSet set = readMmpld(referencePath(r), quietFrame());
  const std::vector<Expected> expected = expectedParticles(r);
  ASSERT_EQ(set.size(), expected.size());
  // One global radius unless the file has per-particle radii; colors per particle unless the file has
  // a single uncolored list.
  EXPECT_EQ(set.perParticleRadius(), r.vertex == MmpldVertex::FloatXyzr);
  EXPECT_EQ(set.perParticleColor(), r.color != MmpldColor::None || r.vertex == MmpldVertex::DoubleXyz);
  Bounds bounds;
  for (uint64_t i = 0; i < set.size(); ++i) {
    EXPECT_LT(glm::length(set.world(i) - expected[i].position), 1e-6) << r.name << " particle " << i;
    EXPECT_EQ(set.radiusOf(i), expected[i].radius) << r.name << " particle " << i;
    EXPECT_EQ(set.colorOf(i), expected[i].color) << r.name << " particle " << i;
    bounds.expand(expected[i].position);
  }
  EXPECT_LT(glm::length(set.bounds.min - bounds.min), 1e-6);
  EXPECT_LT(glm::length(set.bounds.max - bounds.max), 1e-6);
  if (r.vertex != MmpldVertex::DoubleXyz) {
    EXPECT_EQ(set.origin, glm::dvec3(0));
  } // floats kept exactly
  EXPECT_EQ(set.source, std::string(r.name) + ".mmpld");
}

TEST_P(ReferenceFile, ScanAgreesWithTheParticles) {
  POINTRAST_REQUIRE_DATA();
  const Reference& r = GetParam();
  const MmpldStats stats = scanMmpld(referencePath(r), quietFrame());
  const bool isDouble = r.vertex == MmpldVertex::DoubleXyz;
  EXPECT_EQ(stats.particles, isDouble ? 19u : 4u);
  EXPECT_EQ(stats.dropped, 0u);
  EXPECT_EQ(stats.radiusMin, r.vertex == MmpldVertex::FloatXyzr ? 0.2f : 0.1f);
  EXPECT_EQ(stats.radiusMax, r.vertex == MmpldVertex::FloatXyzr ? 0.5f : 0.1f);
  EXPECT_LT(glm::length(stats.centers.min - glm::dvec3(isDouble ? -2 : 0)), 1e-6);
  EXPECT_LT(glm::length(stats.centers.max - glm::dvec3(isDouble ? 2 : 1)), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Mmpld, ReferenceFile, ::testing::ValuesIn(kReferences),
                         [](const auto& param) { return std::string(param.param.name); });

TEST(MmpldReader, EveryReferenceFileIsThere) {
  POINTRAST_REQUIRE_DATA("mmpld");
  // The data folder's seventeen files, each covered above.
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(data("mmpld")))
    files += entry.path().extension() == ".mmpld";
  EXPECT_EQ(files, int(std::size(kReferences)));
}

TEST(MmpldReader, ChunksOfOneParticleReadTheSame) {
  POINTRAST_REQUIRE_DATA();
  for (const char* name :
       {"mmpld/test_xyz_double_rgba_short.mmpld", "mmpld/test_xyzr_float_int_float.mmpld"}) {
    const ParticleSet whole = readMmpld(data(name), quietFrame());
    pointrast::io::detail::setMmpldChunkBytes(1);
    const ParticleSet chunked = readMmpld(data(name), quietFrame());
    pointrast::io::detail::setMmpldChunkBytes(0);
    EXPECT_EQ(chunked.xyz, whole.xyz) << name;
    EXPECT_EQ(chunked.radius, whole.radius) << name;
    EXPECT_EQ(chunked.colors, whole.colors) << name;
  }
}

TEST(MmpldReader, PointReadersRefuseParticleFiles) {
  POINTRAST_REQUIRE_DATA("mmpld/test_xyz_float_none.mmpld");
  try {
    readCloud(data("mmpld/test_xyz_float_none.mmpld"), iotest::quiet());
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("particles"), std::string::npos) << e.what();
  }
  EXPECT_THROW(probeFile(data("mmpld/test_xyz_float_none.mmpld")), InputError);
}

// ---- versions and types the reference files lack -------------------------------------------------------

// The same two lists under every version: FLOAT_XYZ + NONE, and FLOAT_XYZR + UINT8_RGBA.
FrameSpec twoLists() {
  FrameSpec f;
  f.lists.push_back(floatList({{1, 2, 3}, {4, 5, 6}}, packRgba(10, 20, 30, 40), 0.25f));
  ListSpec l;
  l.vertex = 2;
  l.color = 2;
  l.count = 2;
  l.particles = Particles()
                    .add(7.f, 8.f, 9.f, 0.5f, uint32_t(packRgba(1, 2, 3, 4)))
                    .add(-1.f, -2.f, -3.f, 1.5f, uint32_t(packRgba(5, 6, 7, 8)))
                    .bytes;
  l.clusters = {1, 2, 3, 4, 5};
  f.lists.push_back(l);
  return f;
}

void expectTwoLists(const ParticleSet& set) {
  ASSERT_EQ(set.size(), 4u);
  const glm::dvec3 p[4] = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}, {-1, -2, -3}};
  const float r[4] = {0.25f, 0.25f, 0.5f, 1.5f};
  const uint32_t c[4] = {packRgba(10, 20, 30, 40), packRgba(10, 20, 30, 40), packRgba(1, 2, 3, 4),
                         packRgba(5, 6, 7, 8)};
  for (uint64_t i = 0; i < 4; ++i) {
    EXPECT_EQ(set.world(i), p[i]) << i;
    EXPECT_EQ(set.radiusOf(i), r[i]) << i;
    EXPECT_EQ(set.colorOf(i), c[i]) << i;
  }
}

TEST(MmpldReader, EveryVersionReadsTheSameParticles) {
  iotest::TempDir dir;
  for (uint16_t version : {100, 101, 102, 103}) {
    auto path = dir / ("v" + std::to_string(version) + ".mmpld");
    iotest::writeBytes(path, buildMmpld(version, {twoLists()}));
    SCOPED_TRACE(version);
    const MmpldInfo info = probeMmpld(path);
    EXPECT_EQ(info.version, version);
    EXPECT_EQ(info.hasTimestamp, version >= 102);
    if (version >= 102) {
      EXPECT_EQ(info.timestamp, 0.5f);
    }
    ASSERT_EQ(info.lists.size(), 2u);
    EXPECT_EQ(info.lists[1].hasBounds, version == 103);
    if (version == 103) {
      EXPECT_EQ(info.lists[1].bounds.max, glm::dvec3(1));
    }
    expectTwoLists(readMmpld(path, quietFrame()));
  }
}

TEST(MmpldReader, OldMegaMolVersion13FramesWithoutTimestamp) {
  // Older MegaMol wrote 1.3 without the frame timestamp; the lists then fill the frame exactly
  // only when read without one.
  iotest::TempDir dir;
  FrameSpec f = twoLists();
  f.timestamp13 = false;
  iotest::writeBytes(dir / "old.mmpld", buildMmpld(103, {f, f}));
  for (uint32_t frame : {0u, 1u}) {
    const MmpldInfo info = probeMmpld(dir / "old.mmpld", frame);
    EXPECT_FALSE(info.hasTimestamp);
    EXPECT_TRUE(info.timestampMissing);
    expectTwoLists(readMmpld(dir / "old.mmpld", quietFrame(frame)));
  }
}

TEST(MmpldReader, FramesAreSelectedByIndex) {
  iotest::TempDir dir;
  std::vector<FrameSpec> frames;
  for (int k = 0; k < 3; ++k) {
    FrameSpec f;
    f.timestamp = float(k);
    for (int l = 0; l <= k; ++l)
      f.lists.push_back(floatList({{float(k), float(l), 0}}));
    frames.push_back(f);
  }
  iotest::writeBytes(dir / "f.mmpld", buildMmpld(102, frames));
  for (uint32_t k = 0; k < 3; ++k) {
    const MmpldInfo info = probeMmpld(dir / "f.mmpld", k);
    EXPECT_EQ(info.frames, 3u);
    EXPECT_EQ(info.timestamp, float(k));
    const ParticleSet set = readMmpld(dir / "f.mmpld", quietFrame(k));
    ASSERT_EQ(set.size(), k + 1);
    EXPECT_EQ(set.world(k), glm::dvec3(k, k, 0));
    EXPECT_EQ(set.source, "f.mmpld, frame " + std::to_string(k));
  }
  try {
    readMmpld(dir / "f.mmpld", quietFrame(3));
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("there is no frame 3: the file has 3 frames (0 to 2)"),
              std::string::npos)
        << e.what();
  }
}

TEST(MmpldReader, ShortPositionsRgbBytesAndSkippedLists) {
  iotest::TempDir dir;
  FrameSpec f;
  ListSpec none; // no positions: skipped, whatever count it states
  none.vertex = 0;
  none.count = 1'000'000'000;
  f.lists.push_back(none);
  ListSpec shorts;
  shorts.vertex = 3;
  shorts.color = 1;
  shorts.radius = 2;
  shorts.count = 2;
  shorts.particles = Particles()
                         .add(int16_t(-32768), int16_t(7), int16_t(32767))
                         .add(uint8_t(9), uint8_t(8), uint8_t(7))
                         .add(int16_t(1), int16_t(-2), int16_t(3))
                         .add(uint8_t(255), uint8_t(0), uint8_t(128))
                         .bytes;
  f.lists.push_back(shorts);
  iotest::writeBytes(dir / "s.mmpld", buildMmpld(102, {f}));
  const MmpldInfo info = probeMmpld(dir / "s.mmpld");
  ASSERT_EQ(info.lists.size(), 2u);
  EXPECT_FALSE(info.lists[0].hasPositions());
  EXPECT_EQ(info.particles(), 2u);
  const ParticleSet set = readMmpld(dir / "s.mmpld", quietFrame());
  ASSERT_EQ(set.size(), 2u);
  EXPECT_EQ(set.world(0), glm::dvec3(-32768, 7, 32767));
  EXPECT_EQ(set.world(1), glm::dvec3(1, -2, 3));
  EXPECT_FALSE(set.perParticleRadius());
  EXPECT_EQ(set.globalRadius, 2.0f);
  EXPECT_EQ(set.colorOf(0), packRgba(9, 8, 7));
  EXPECT_EQ(set.colorOf(1), packRgba(255, 0, 128));
}

TEST(MmpldReader, FarDoublePositionsKeepTheirPrecision) {
  // UTM-like coordinates: a float keeps 0.03 m there, the set keeps far better than a millimetre.
  iotest::TempDir dir;
  FrameSpec f;
  ListSpec l;
  l.vertex = 4;
  l.color = 6;
  l.count = 3;
  const glm::dvec3 p[3] = {
      {500000.001, 4000000.002, 100.003}, {500010.5, 4000020.25, 99.125}, {499990.0, 3999990.0, 101}};
  Particles bytes;
  for (const auto& q : p)
    bytes.add(q.x, q.y, q.z, uint16_t(65535), uint16_t(257 * 128), uint16_t(0), uint16_t(32768));
  l.particles = bytes.bytes;
  f.lists.push_back(l);
  iotest::writeBytes(dir / "utm.mmpld", buildMmpld(102, {f}));
  const ParticleSet set = readMmpld(dir / "utm.mmpld", quietFrame());
  ASSERT_EQ(set.size(), 3u);
  EXPECT_EQ(set.origin, glm::dvec3(500000.25, 4000005.125, 100.0625)); // the bounds' center
  for (int i = 0; i < 3; ++i)
    EXPECT_LT(glm::length(set.world(i) - p[i]), 1e-5) << i;
  EXPECT_EQ(set.colorOf(0), packRgba(255, 128, 0, 128)); // 16-bit channels to the nearest 8-bit value
}

TEST(MmpldReader, IntensityRangesMapOntoTheRamp) {
  iotest::TempDir dir;
  FrameSpec f;
  ListSpec stated; // stated range 10..20: 15 is the middle, values outside clamp
  stated.color = 3;
  stated.range[0] = 10;
  stated.range[1] = 20;
  stated.count = 3;
  stated.particles =
      Particles().add(0.f, 0.f, 0.f, 15.f).add(1.f, 0.f, 0.f, 30.f).add(2.f, 0.f, 0.f, -5.f).bytes;
  ListSpec empty = stated; // empty stated range (MegaMol's default 0..-1 has max < min): the values' own
  empty.color = 7;
  empty.range[0] = 0;
  empty.range[1] = -1;
  empty.particles =
      Particles().add(0.f, 1.f, 0.f, 100.0).add(1.f, 1.f, 0.f, 300.0).add(2.f, 1.f, 0.f, 200.0).bytes;
  ListSpec constant = stated; // one value throughout: the middle of the ramp
  constant.range[0] = constant.range[1] = 7;
  constant.particles =
      Particles().add(0.f, 2.f, 0.f, 7.f).add(1.f, 2.f, 0.f, 7.f).add(2.f, 2.f, 0.f, NAN).bytes;
  f.lists = {stated, empty, constant};
  iotest::writeBytes(dir / "i.mmpld", buildMmpld(102, {f}));
  const ParticleSet set = readMmpld(dir / "i.mmpld", quietFrame());
  ASSERT_EQ(set.size(), 9u);
  // A NaN intensity takes the low end of the ramp.
  const uint32_t expected[9] = {particleRamp(0.5), particleRamp(1),   particleRamp(0),
                                particleRamp(0),   particleRamp(1),   particleRamp(0.5),
                                particleRamp(0.5), particleRamp(0.5), particleRamp(0)};
  for (int i = 0; i < 9; ++i)
    EXPECT_EQ(set.colors[i], expected[i]) << i;
  EXPECT_NE(particleRamp(0), particleRamp(1));
}

TEST(MmpldReader, GlobalRadiiAndColorsAreKeptOnlyWhenAllListsAgree) {
  iotest::TempDir dir;
  FrameSpec same;
  same.lists = {floatList({{0, 0, 0}}, 0xFF0000FFu, 0.5f), floatList({{1, 1, 1}}, 0xFF0000FFu, 0.5f)};
  iotest::writeBytes(dir / "same.mmpld", buildMmpld(100, {same}));
  ParticleSet set = readMmpld(dir / "same.mmpld", quietFrame());
  EXPECT_FALSE(set.perParticleRadius());
  EXPECT_FALSE(set.perParticleColor());
  EXPECT_EQ(set.globalRadius, 0.5f);
  EXPECT_EQ(set.globalColor, 0xFF0000FFu);

  FrameSpec differ;
  differ.lists = {floatList({{0, 0, 0}}, 0xFF0000FFu, 0.5f),
                  floatList({{1, 1, 1}, {2, 2, 2}}, 0xFF00FF00u, 0.75f)};
  iotest::writeBytes(dir / "differ.mmpld", buildMmpld(100, {differ}));
  set = readMmpld(dir / "differ.mmpld", quietFrame());
  EXPECT_EQ(set.radius, (std::vector<float>{0.5f, 0.75f, 0.75f}));
  EXPECT_EQ(set.colors, (std::vector<uint32_t>{0xFF0000FFu, 0xFF00FF00u, 0xFF00FF00u}));
}

TEST(MmpldReader, BadParticlesAreDroppedAcrossChunksAndBlocks) {
  // 200,000 particles (four 65536-particle blocks in one chunk), some with NaN or infinite coordinates
  // or bad radii, and a second list; read whole and in chunks of a few particles.
  iotest::TempDir dir;
  const uint64_t n = 200'000;
  ListSpec big;
  big.vertex = 2;
  big.color = 0;
  big.count = n;
  std::vector<glm::vec4> kept;
  Particles bytes;
  const float inf = std::numeric_limits<float>::infinity();
  for (uint64_t i = 0; i < n; ++i) {
    glm::vec4 p(float(i), float(i % 7), -float(i % 13), 0.5f + float(i % 3));
    if (i % 50'001 == 3) p.y = NAN;
    if (i % 70'001 == 9) p.z = -inf;
    if (i % 90'001 == 5) p.w = -1;
    if (i % 90'001 == 6) p.w = NAN;
    bytes.add(p.x, p.y, p.z, p.w);
    if (std::isfinite(p.y) && std::isfinite(p.z) && p.w >= 0) kept.push_back(p);
  }
  big.particles = bytes.bytes;
  FrameSpec f;
  f.lists = {big, floatList({{-1, -2, -3}})};
  iotest::writeBytes(dir / "big.mmpld", buildMmpld(103, {f}));
  for (uint64_t chunk : {uint64_t(0), uint64_t(16 * 1000 + 5)}) {
    pointrast::io::detail::setMmpldChunkBytes(chunk);
    const ParticleSet set = readMmpld(dir / "big.mmpld", quietFrame());
    const MmpldStats stats = scanMmpld(dir / "big.mmpld", quietFrame());
    pointrast::io::detail::setMmpldChunkBytes(0);
    SCOPED_TRACE(chunk);
    ASSERT_EQ(set.size(), kept.size() + 1);
    EXPECT_EQ(stats.particles, set.size());
    EXPECT_EQ(stats.dropped, n - kept.size());
    EXPECT_EQ(n - kept.size(), 4u + 3u + 3u + 3u);
    for (uint64_t i = 0; i < kept.size(); ++i) {
      ASSERT_EQ(set.world(i), glm::dvec3(kept[i])) << i;
      ASSERT_EQ(set.radius[i], kept[i].w) << i;
    }
    EXPECT_EQ(set.world(kept.size()), glm::dvec3(-1, -2, -3));
    EXPECT_EQ(set.radius.back(), 0.1f);
    EXPECT_EQ(stats.radiusMin, 0.1f);
    EXPECT_EQ(stats.radiusMax, 2.5f);
    EXPECT_EQ(stats.centers.min, glm::dvec3(-1, -2, -12));
    EXPECT_EQ(stats.centers.max, glm::dvec3(double(n - 1), 6, 0));
    EXPECT_EQ(set.bounds.min, stats.centers.min);
    EXPECT_EQ(set.bounds.max, stats.centers.max);
  }
}

// ---- writer round trips -------------------------------------------------------------------------------

ParticleSet randomSet(uint64_t n, bool perRadius, bool perColor, glm::dvec3 origin = glm::dvec3(0)) {
  iotest::Lcg rng(9);
  ParticleSet set;
  set.origin = origin;
  set.globalRadius = 0.375f;
  set.globalColor = packRgba(1, 2, 3, 4);
  for (uint64_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a)
      set.xyz.push_back(float(rng.uniform() * 200 - 100));
    if (perRadius) set.radius.push_back(float(rng.uniform() * 2));
    if (perColor) set.colors.push_back(rng.next());
  }
  computeBounds(set);
  return set;
}

TEST(MmpldWriter, RoundTripsEveryLayoutAndVersion) {
  iotest::TempDir dir;
  for (MmpldVersion version : {MmpldVersion::V1_0, MmpldVersion::V1_3})
    for (bool perRadius : {false, true})
      for (bool perColor : {false, true}) {
        SCOPED_TRACE(testing::Message() << int(version) << perRadius << perColor);
        const ParticleSet set = randomSet(70'000, perRadius, perColor);
        writeMmpld(dir / "rt.mmpld", set, version);
        EXPECT_FALSE(std::filesystem::exists(dir / "rt.mmpld.partial"));
        const MmpldInfo info = probeMmpld(dir / "rt.mmpld");
        EXPECT_EQ(info.version, version == MmpldVersion::V1_0 ? 100 : 103);
        EXPECT_EQ(info.frames, 1u);
        ASSERT_EQ(info.lists.size(), 1u);
        EXPECT_EQ(info.lists[0].vertex, perRadius ? MmpldVertex::FloatXyzr : MmpldVertex::FloatXyz);
        EXPECT_EQ(info.lists[0].color, perColor ? MmpldColor::Uint8Rgba : MmpldColor::None);
        const Bounds spheres = sphereBounds(set);
        for (int a = 0; a < 3; ++a) {
          EXPECT_EQ(info.bbox.min[a], double(float(spheres.min[a])));
          EXPECT_EQ(info.clipBox.max[a], double(float(spheres.max[a])));
        }
        EXPECT_EQ(info.lists[0].hasBounds, version == MmpldVersion::V1_3);
        const ParticleSet back = readMmpld(dir / "rt.mmpld", quietFrame());
        EXPECT_EQ(back.xyz, set.xyz); // origin 0: positions exact
        EXPECT_EQ(back.radius, set.radius);
        EXPECT_EQ(back.colors, set.colors);
        if (!perRadius) {
          EXPECT_EQ(back.globalRadius, set.globalRadius);
        }
        if (!perColor) {
          EXPECT_EQ(back.globalColor, set.globalColor);
        }
        EXPECT_EQ(back.bounds.min, set.bounds.min);
        EXPECT_EQ(back.bounds.max, set.bounds.max);
      }
}

TEST(MmpldWriter, WorldCoordinatesAndEmptySets) {
  iotest::TempDir dir;
  // MMPLD holds float world coordinates: a set with an origin is written at origin + xyz.
  const ParticleSet far = randomSet(100, false, false, glm::dvec3(1000, -2000, 50));
  writeMmpld(dir / "far.mmpld", far);
  const ParticleSet back = readMmpld(dir / "far.mmpld", quietFrame());
  ASSERT_EQ(back.size(), far.size());
  for (uint64_t i = 0; i < far.size(); ++i)
    ASSERT_LT(glm::length(back.world(i) - far.world(i)), 2e-4) << i;

  writeMmpld(dir / "empty.mmpld", ParticleSet{}, MmpldVersion::V1_0);
  EXPECT_EQ(readMmpld(dir / "empty.mmpld", quietFrame()).size(), 0u);
  EXPECT_EQ(probeMmpld(dir / "empty.mmpld").particles(), 0u);
}

TEST(MmpldWriter, RefusesBadRadiiAndLeavesNothing) {
  iotest::TempDir dir;
  ParticleSet set = randomSet(10, false, false);
  set.globalRadius = NAN;
  EXPECT_THROW(writeMmpld(dir / "bad.mmpld", set), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.mmpld"));
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.mmpld.partial"));
  EXPECT_THROW(writeMmpld(dir / "no-such-dir" / "x.mmpld", randomSet(10, false, false)), InputError);
}

// ---- hostile input ------------------------------------------------------------------------------------

// readMmpld, probeMmpld and scanMmpld on a possibly hostile file: each must succeed or throw InputError.
iotest::Outcome readOrRefuse(const std::filesystem::path& path) {
  iotest::Outcome outcome = iotest::Outcome::Read;
  try {
    const ParticleSet set = readMmpld(path, quietFrame());
    EXPECT_EQ(set.xyz.size(), 3 * set.size());
    EXPECT_TRUE(set.radius.empty() || set.radius.size() == set.size());
    EXPECT_TRUE(set.colors.empty() || set.colors.size() == set.size());
  } catch (const InputError&) {
    outcome = iotest::Outcome::Refused;
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": readMmpld threw a non-InputError: " << e.what();
  }
  for (auto probe : {+[](const std::filesystem::path& p) { probeMmpld(p); },
                     +[](const std::filesystem::path& p) { scanMmpld(p, quietFrame()); }}) {
    try {
      probe(path);
    } catch (const InputError&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << path << ": probe/scan threw a non-InputError: " << e.what();
    }
  }
  return outcome;
}

std::vector<std::vector<uint8_t>> hostileSeeds() {
  FrameSpec withClusters = twoLists();
  return {iotest::readBytes(data("mmpld/test_xyz_double_int_double.mmpld")),
          iotest::readBytes(data("mmpld/test_xyzr_float_rgba_byte.mmpld")), buildMmpld(101, {withClusters}),
          buildMmpld(103, {twoLists(), twoLists()})};
}

TEST(MmpldHostile, EveryPrefixIsRefused) {
  POINTRAST_REQUIRE_DATA();
  iotest::TempDir dir;
  for (const auto& bytes : hostileSeeds()) {
    for (size_t len = 0; len < bytes.size(); ++len) {
      iotest::writeBytes(dir / "t.mmpld", bytes.data(), len);
      ASSERT_EQ(readOrRefuse(dir / "t.mmpld"), iotest::Outcome::Refused) << "prefix " << len;
    }
    iotest::writeBytes(dir / "t.mmpld", bytes);
    EXPECT_EQ(readOrRefuse(dir / "t.mmpld"), iotest::Outcome::Read);
  }
}

TEST(MmpldHostile, FlippedBytesReadOrRefuse) {
  POINTRAST_REQUIRE_DATA();
  iotest::TempDir dir;
  for (const auto& bytes : hostileSeeds()) {
    std::vector<uint8_t> copy = bytes;
    for (size_t i = 0; i < bytes.size(); ++i) {
      for (uint8_t v : {uint8_t(0x00), uint8_t(0xFF), uint8_t(bytes[i] ^ 0x80)}) {
        copy[i] = v;
        iotest::writeBytes(dir / "f.mmpld", copy);
        readOrRefuse(dir / "f.mmpld");
      }
      copy[i] = bytes[i];
      if (HasFailure()) return;
    }
  }
}

// One clear sentence for each kind of lie.
void expectRefused(const std::vector<uint8_t>& bytes, const std::string& phrase, uint32_t frame = 0) {
  iotest::TempDir dir;
  iotest::writeBytes(dir / "h.mmpld", bytes);
  try {
    readMmpld(dir / "h.mmpld", quietFrame(frame));
    ADD_FAILURE() << "read, expected: " << phrase;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(phrase), std::string::npos) << message;
    EXPECT_NE(message.find("h.mmpld"), std::string::npos) << message; // names the file
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

template <class T> std::vector<uint8_t> patched(std::vector<uint8_t> bytes, size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof value);
  return bytes;
}

TEST(MmpldHostile, EachLieGetsOneClearSentence) {
  // Offsets in the 1.2 file built from one FLOAT_XYZ list: header 60, table 76, timestamp 76, list count
  // 80, vertex type 84, color type 85, radius 86, color 90, count 94, particles 102.
  FrameSpec f;
  f.lists = {floatList({{1, 2, 3}, {4, 5, 6}})};
  const std::vector<uint8_t> good = buildMmpld(102, {f});
  ASSERT_EQ(good.size(), 102u + 24u);
  expectRefused(std::vector<uint8_t>(good.begin(), good.begin() + 40), "shorter than the 60-byte header");
  expectRefused(patched(good, 0, 'X'), "not an MMPLD file");
  expectRefused(patched<uint16_t>(good, 6, 0), "not completely written");
  expectRefused(patched<uint16_t>(good, 6, 99), "not supported");
  expectRefused(patched<uint16_t>(good, 6, 104), "not supported");
  expectRefused(patched<uint32_t>(good, 8, 0), "no frames");
  expectRefused(patched<uint32_t>(good, 8, 0xFFFFFFFF), "frame table of 4294967295 frames");
  expectRefused(good, "there is no frame 1", 1);
  expectRefused(patched<uint64_t>(good, 68, 1000), "truncated: the frame table ends the file at byte 1000");
  expectRefused(patched<uint64_t>(good, 60, 8), "corrupt frame table");
  expectRefused(patched<uint64_t>(good, 60, 200), "corrupt frame table");
  expectRefused(patched<uint32_t>(good, 80, 0xFFFFFFFF), "declares 4294967295 particle lists");
  expectRefused(patched<uint32_t>(good, 80, 2), "list 1's header runs past the end of the frame");
  expectRefused(patched<uint8_t>(good, 84, 5), "unknown vertex type 5");
  expectRefused(patched<uint8_t>(good, 85, 8), "unknown color type 8");
  expectRefused(patched<float>(good, 86, -1.0f), "global radius");
  expectRefused(patched<float>(good, 86, NAN), "global radius");
  expectRefused(patched<uint64_t>(good, 94, 3), "3 particles of 12 bytes do not fit");
  expectRefused(patched<uint64_t>(good, 94, ~uint64_t(0)), "do not fit");
  expectRefused(patched<uint64_t>(good, 94, uint64_t(1) << 62), "do not fit");
  // 1.1: the cluster data size after the list.
  FrameSpec clusters = twoLists();
  std::vector<uint8_t> v11 = buildMmpld(101, {clusters});
  const size_t sizeAt = v11.size() - clusters.lists[1].clusters.size() - 8;
  expectRefused(patched<uint64_t>(v11, sizeAt, uint64_t(1) << 63),
                "cluster data runs past the end of the frame");
}

} // namespace
