// COPC files written by the octree builder, read back by pointrast's COPC reader: the same nodes holding
// the same points (per node, as multisets) as the Potree folder of the same build, the info VLR first with
// the builder's cube and spacing, hierarchy pages crossed, the inputs' WKT kept, the same bytes from one
// thread and out of core, and what `info` says of the colors.
#include <thread>

#include "io/copc_build_test_util.h"
#include "io/io_test_util.h"
#include "io/las/las_format.h"
#include "io/writer.h"

#include "cloud/generate.h"

namespace {

using namespace pointrast;
using namespace copctest;
namespace las = io::detail::las;

void expectSameOctree(const Builds& b) {
  std::unique_ptr<lod::NodeSource> potree = io::openPotree(b.potree);
  std::unique_ptr<lod::NodeSource> copc = io::openCopc(b.copc);
  const lod::OctreeMetadata& p = potree->metadata();
  const lod::OctreeMetadata& c = copc->metadata();
  EXPECT_EQ(c.format, "COPC 1.0");
  EXPECT_EQ(c.pointCount, p.pointCount);
  EXPECT_EQ(c.spacing, p.spacing);
  EXPECT_EQ(c.scale, p.scale);
  EXPECT_EQ(c.offset, p.offset);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(c.cube.min[a], p.cube.min[a], 1e-9 * (p.cube.max.x - p.cube.min.x)) << a;
    EXPECT_NEAR(c.cube.max[a], p.cube.max[a], 1e-9 * (p.cube.max.x - p.cube.min.x)) << a;
    EXPECT_EQ(c.bounds.min[a], p.bounds.min[a]) << a;
    EXPECT_EQ(c.bounds.max[a], p.bounds.max[a]) << a;
  }
  EXPECT_EQ(c.fields.color, p.fields.color);
  const Nodes pn = readNodes(*potree), cn = readNodes(*copc);
  EXPECT_GT(pn.size(), 8u);
  ASSERT_EQ(cn.size(), pn.size());
  uint64_t points = 0;
  for (const auto& [key, records] : pn) {
    const auto it = cn.find(key);
    ASSERT_NE(it, cn.end()) << key.potreeName() << " is missing from the COPC file";
    EXPECT_TRUE(it->second == records) << key.potreeName() << " holds other points";
    points += records.size();
  }
  EXPECT_EQ(points, p.pointCount);
}

// The first VLR's user id and record id, read at offset 375 as a COPC reader does.
void expectInfoVlrFirst(const std::vector<uint8_t>& bytes) {
  ASSERT_GT(bytes.size(), 549u);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(bytes.data() + 377), 4), "copc");
  EXPECT_EQ(bytes[393], 1);
  EXPECT_EQ(bytes[394], 0);
  const int format = bytes[las::kPointFormat] & 0x3F;
  EXPECT_TRUE(format == 6 || format == 7) << format;
}

TEST(CopcWriter, GeneratedCloudHoldsThePotreeBuildsNodes) {
  iotest::TempDir dir;
  GenerateOptions g;
  g.points = 60'000;
  g.progress = false;
  io::writeLas(dir / "t.las", generateScene(Scene::Terrain, g), io::LasFlavor::Las12Pf2);
  io::LodBuildOptions options;
  options.leafPoints = 3'000;
  io::CopcWriteOptions copc;
  copc.hierarchyStepSize = 1; // a page a level: the reader crosses pages
  const Builds b = buildBoth({dir / "t.las"}, dir / "a", options, copc);
  expectSameOctree(b);
  const std::vector<uint8_t> bytes = iotest::readBytes(b.copc);
  expectInfoVlrFirst(bytes);
  EXPECT_EQ(bytes[las::kPointFormat] & 0x3F, 7); // colors
  EXPECT_EQ(b.copcReport.bytes, bytes.size());
  const std::optional<io::CopcSummary> summary = io::summarizeCopc(b.copc);
  ASSERT_TRUE(summary);
  EXPECT_GT(summary->pages, 1u);
  EXPECT_NE(summary->colors.find("averaged colors"), std::string::npos) << summary->colors;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "a"))
    EXPECT_TRUE(entry.path().filename() == "potree" || entry.path().filename() == "octree.copc.laz")
        << "left behind: " << entry.path();

  // The same bytes from one thread, out of core (chunk files in the writer's temporary folder).
  options.threads = 1;
  options.memoryBytes = 3 << 20;
  options.progress = false;
  const io::CopcBuildReport spilled = io::buildCopc({dir / "t.las"}, dir / "b.copc.laz", options, copc);
  EXPECT_TRUE(spilled.build.outOfCore);
  EXPECT_TRUE(iotest::readBytes(dir / "b.copc.laz") == bytes);

  // Exact colors: other inner nodes, and `info` says so.
  options = {};
  options.leafPoints = 3'000;
  options.averageColors = false;
  const Builds exact = buildBoth({dir / "t.las"}, dir / "c", options);
  expectSameOctree(exact);
  const std::optional<io::CopcSummary> own = io::summarizeCopc(exact.copc);
  ASSERT_TRUE(own);
  EXPECT_EQ(own->pages, 1u);
  EXPECT_NE(own->colors.find("its own color"), std::string::npos) << own->colors;
  EXPECT_FALSE(iotest::readBytes(exact.copc) == bytes);
}

// The WKT VLR's payload of a LAS file (up to its null), empty when it has none.
std::string wktOf(const std::filesystem::path& path) {
  const io::detail::InputFile file(path);
  const io::detail::LasHeader hd = io::detail::readLasHeader(file, true);
  for (const io::detail::LasVlr& vlr : hd.vlrs)
    if (vlr.userId == "LASF_Projection" && vlr.recordId == 2112) {
      std::string s(vlr.length, '\0');
      file.readAt(vlr.dataOffset, s.data(), s.size());
      return s.c_str();
    }
  return {};
}

TEST(CopcWriter, AutzenKeepsItsCoordinateSystemAndNodes) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  iotest::TempDir dir;
  const std::filesystem::path input = iotest::data("las/autzen_trim.las");
  io::LodBuildOptions options;
  options.leafPoints = 4'000;
  const Builds b = buildBoth({input}, dir.path(), options);
  expectSameOctree(b);
  const std::vector<uint8_t> bytes = iotest::readBytes(b.copc);
  expectInfoVlrFirst(bytes);
  EXPECT_EQ(io::detail::loadLE<uint16_t>(bytes.data() + las::kGlobalEncoding) & 0x10, 0x10); // WKT bit
  const std::string wkt = wktOf(input);
  ASSERT_FALSE(wkt.empty());
  EXPECT_EQ(wktOf(b.copc), wkt);
  EXPECT_EQ(io::inputsWkt({input, input}), wkt);
}

TEST(CopcWriter, InputsWithDifferentCoordinateSystemsAreRefused) {
  POINTRAST_REQUIRE_DATA("las/warsaw_small.las");
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  iotest::TempDir dir;
  io::LodBuildOptions options;
  options.progress = false;
  const std::filesystem::path out = dir / "o.copc.laz";
  try {
    io::buildCopc({iotest::data("las/autzen_trim.las"), iotest::data("las/warsaw_small.las")}, out, options);
    ADD_FAILURE() << "two coordinate systems in one COPC file were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("coordinate system (WKT) differs"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

// Nodes take their offsets in the order their turns were reserved, whatever order their encodings
// arrive in and on whichever thread: filled at once, filled backwards from several threads, or left
// waiting by writeNode() and encoded later, the file is the same, and holds every node's points.
TEST(CopcWriter, NodesFilledInAnyOrderGiveTheSameBytes) {
  iotest::TempDir dir;
  lod::OctreeMetadata m;
  m.cube.min = glm::dvec3(0.0);
  m.cube.max = glm::dvec3(64.0);
  m.spacing = 0.5;
  m.scale = glm::dvec3(0.001);
  m.fields.color = m.fields.intensity = m.fields.classification = true;
  // The root and its eight children, 50 to 750 points each, in post-order as the builder hands them.
  std::vector<std::pair<lod::NodeKey, std::vector<PointRecord>>> nodes;
  uint32_t seed = 7;
  auto next = [&] { return seed = seed * 1664525u + 1013904223u; };
  for (int i = 0; i <= 8; ++i) {
    const lod::NodeKey key = i < 8 ? lod::NodeKey{}.child(i) : lod::NodeKey{};
    const double edge = i < 8 ? 32.0 : 64.0;
    std::vector<PointRecord> records(50 + 100 * size_t(i % 8));
    for (PointRecord& r : records) {
      const glm::dvec3 lo = m.nodeCube(key).min;
      r.x = int32_t((lo.x + edge * (next() % 1000) / 1000.0) / m.scale.x);
      r.y = int32_t((lo.y + edge * (next() % 1000) / 1000.0) / m.scale.y);
      r.z = int32_t((lo.z + edge * (next() % 1000) / 1000.0) / m.scale.z);
      r.rgb[0] = uint16_t(next()), r.rgb[1] = uint16_t(next()), r.rgb[2] = uint16_t(next());
      r.intensity = uint16_t(next());
      r.classification = uint8_t(next() % 32);
      r.returnNumber = 1; // what a record without return numbers is written with
    }
    nodes.emplace_back(key, std::move(records));
  }
  auto write = [&](const std::filesystem::path& path, int mode) {
    io::CopcWriter writer(path, m, false, {});
    std::vector<uint64_t> turns;
    if (mode == 0) {
      for (const auto& [key, records] : nodes)
        writer.fill(writer.reserve(key), writer.encodeNode(key, records.data(), records.size()));
    } else if (mode == 1) {
      for (const auto& [key, records] : nodes)
        turns.push_back(writer.reserve(key));
      std::vector<std::thread> threads;
      for (int t = 0; t < 3; ++t)
        threads.emplace_back([&, t] {
          for (size_t i = nodes.size(); i-- > 0;)
            if (int(i % 3) == t)
              writer.fill(turns[i],
                          writer.encodeNode(nodes[i].first, nodes[i].second.data(), nodes[i].second.size()));
        });
      for (std::thread& t : threads)
        t.join();
    } else {
      // Every other node waits; the last ones are encoded by commit().
      for (size_t i = 0; i < nodes.size(); ++i) {
        const auto& [key, records] = nodes[i];
        if (i % 2 == 0) {
          writer.writeNode(key, records.data(), records.size());
        } else {
          writer.fill(writer.reserve(key), writer.encodeNode(key, records.data(), records.size()));
          if (i == 5) writer.compressWaiting();
        }
      }
    }
    writer.commit();
    return iotest::readBytes(path);
  };
  const std::vector<uint8_t> inOrder = write(dir / "a.copc.laz", 0);
  EXPECT_TRUE(write(dir / "b.copc.laz", 1) == inOrder);
  EXPECT_TRUE(write(dir / "c.copc.laz", 2) == inOrder);

  std::unique_ptr<lod::NodeSource> copc = io::openCopc(dir / "c.copc.laz");
  const Nodes read = readNodes(*copc);
  ASSERT_EQ(read.size(), nodes.size());
  for (auto [key, records] : nodes) {
    std::sort(records.begin(), records.end(), recordLess);
    const auto it = read.find(key);
    ASSERT_NE(it, read.end()) << key.potreeName();
    EXPECT_TRUE(it->second == records) << key.potreeName();
  }
}

} // namespace
