// Octrees built from files and written as Potree 2.0 folders, read back through openPotree(): the
// builder's properties hold on what is on disk (every input point once and exact, cubes, leaf limit,
// one point per grid cell, child masks and counts), a write -> read round trip gives the nodes built,
// and the folder's bytes are the same from 1 and 2 threads and out of core.
#include "cloud/lod_test_util.h"
#include "io/io_test_util.h"
#include "io/potree/lod_potree.h"
#include "io/point_source.h"
#include "io/potree/potree_format.h"
#include "io/potree_test_util.h"
#include "io/writer.h"

namespace {

using namespace pointrast;
using namespace pointrast::lodtest;
using iotest::data;

std::vector<PointRecord> readRecords(const std::filesystem::path& path) {
  std::unique_ptr<io::PointSource> source = io::openPointSource(path);
  std::vector<PointRecord> all, piece;
  for (size_t i = 0; i < source->pieces().size(); ++i) {
    source->readPiece(i, piece);
    all.insert(all.end(), piece.begin(), piece.end());
  }
  return all;
}

io::PotreeBuildReport buildTo(const std::filesystem::path& input, const std::filesystem::path& out,
                              io::LodBuildOptions options,
                              io::PotreeEncoding encoding = io::PotreeEncoding::Default) {
  options.progress = false;
  io::PotreeWriteOptions write;
  write.encoding = encoding;
  write.name = "octree"; // the same metadata.json whatever the folder is called
  return io::buildPotree({input}, out, options, write);
}

// Every node as the reader serves it, checked against the hierarchy's own claims on the way.
std::vector<WrittenNode> readOctree(const std::filesystem::path& dir) {
  std::unique_ptr<lod::NodeSource> source = io::openPotree(dir);
  std::map<NodeKey, WrittenNode> nodes;
  std::map<NodeKey, uint8_t> masks;
  lod::forEachNode(*source, [&](const lod::NodeInfo& info) {
    WrittenNode n{info.key, source->readNode(info)};
    EXPECT_EQ(n.records.size(), info.pointCount) << info.key.potreeName();
    masks[info.key] = info.childMask;
    nodes[info.key] = std::move(n);
    return true;
  });
  for (const auto& [key, mask] : masks)
    for (int c = 0; c < 8; ++c)
      EXPECT_EQ(bool(mask >> c & 1), nodes.count(key.child(c)) == 1) << key.potreeName() << " child " << c;
  std::vector<WrittenNode> out;
  for (auto& [key, node] : nodes)
    out.push_back(std::move(node));
  return out;
}

bool sameFiles(const std::filesystem::path& a, const std::filesystem::path& b) {
  for (const char* file : {"metadata.json", "hierarchy.bin", "octree.bin"})
    if (iotest::readBytes(a / file) != iotest::readBytes(b / file)) {
      ADD_FAILURE() << file << " differs between " << a << " and " << b;
      return false;
    }
  return true;
}

class LodPotree : public ::testing::TestWithParam<io::PotreeEncoding> {};

TEST_P(LodPotree, AutzenOnDiskHoldsEveryPointOnceAndRoundTrips) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  iotest::TempDir dir;
  const std::filesystem::path input = data("las/autzen_trim.las");
  const std::vector<PointRecord> records = readRecords(input);
  io::LodBuildOptions options;
  options.leafPoints = 4'000;
  const io::PotreeBuildReport report = buildTo(input, dir / "o", options, GetParam());
  EXPECT_FALSE(std::filesystem::exists(dir / "o" / "chunks"));
  std::vector<WrittenNode> nodes = readOctree(dir / "o");
  EXPECT_EQ(nodes.size(), report.build.octree.nodes);
  const lod::LodGrid grid = gridOf(records, report.build.metadata.scale, report.build.metadata.offset);
  lod::LodParams params;
  params.leafPoints = options.leafPoints;
  // The reader's post-order is not the write order: check the properties on key order.
  std::vector<WrittenNode> postOrder = nodes;
  std::sort(postOrder.begin(), postOrder.end(), [](const WrittenNode& a, const WrittenNode& b) {
    const int level = std::min(a.key.level, b.key.level);
    const uint64_t ca = lod::cellOfKey(a.key) >> 3 * (a.key.level - level);
    const uint64_t cb = lod::cellOfKey(b.key) >> 3 * (b.key.level - level);
    return ca != cb ? ca < cb : a.key.level > b.key.level;
  });
  expectValidOctree(postOrder, records, grid, params);

  // Round trip: the nodes read are the nodes built, record for record.
  MemorySink sink;
  io::LodBuildOptions quiet = options;
  quiet.progress = false;
  io::OctreeBuilder builder({input}, quiet);
  builder.scan();
  builder.build(sink, dir / "tmp");
  ASSERT_EQ(sink.nodes.size(), nodes.size());
  std::map<NodeKey, const WrittenNode*> byKey;
  for (const WrittenNode& n : nodes)
    byKey[n.key] = &n;
  for (const WrittenNode& built : sink.nodes) {
    ASSERT_TRUE(byKey.count(built.key)) << built.key.potreeName();
    const std::vector<PointRecord>& read = byKey[built.key]->records;
    ASSERT_EQ(read.size(), built.records.size());
    for (size_t i = 0; i < read.size(); ++i)
      ASSERT_EQ(read[i], built.records[i]) << built.key.potreeName() << " record " << i;
  }
  // hierarchy.bin itself: child masks, counts and byte ranges agree with the nodes built, and the nodes'
  // byte ranges tile octree.bin exactly.
  const uint64_t octreeBytes = std::filesystem::file_size(dir / "o" / "octree.bin");
  // DEFAULT: 24 bytes of record fields and the attributes autzen's points carry (GPS time...).
  uint64_t stride = 0;
  for (const io::PotreeAttributeInfo& a : io::probePotree(dir / "o").attributes)
    stride += uint64_t(a.size);
  EXPECT_GT(stride, 24u);
  std::vector<std::pair<uint64_t, uint64_t>> ranges;
  std::map<NodeKey, uint8_t> masks;
  for (const potreetest::DiskNode& n : potreetest::walkHierarchy(dir / "o")) {
    if (n.record.type == io::potree::kProxy) continue;
    ASSERT_TRUE(byKey.count(n.key)) << n.key.potreeName();
    EXPECT_EQ(n.record.pointCount, byKey[n.key]->records.size()) << n.key.potreeName();
    EXPECT_EQ(n.record.type, n.record.childMask ? io::potree::kNormal : io::potree::kLeaf);
    if (GetParam() == io::PotreeEncoding::Default) {
      EXPECT_EQ(uint64_t(n.record.byteSize), n.record.pointCount * stride);
    }
    ranges.push_back({n.record.byteOffset, n.record.byteOffset + n.record.byteSize});
    masks[n.key] = n.record.childMask;
  }
  EXPECT_EQ(masks.size(), nodes.size());
  for (const auto& [key, mask] : masks)
    for (int c = 0; c < 8; ++c)
      EXPECT_EQ(bool(mask >> c & 1), byKey.count(key.child(c)) == 1) << key.potreeName() << " child " << c;
  std::sort(ranges.begin(), ranges.end());
  uint64_t at = 0;
  for (const auto& [begin, end] : ranges) {
    EXPECT_EQ(begin, at) << "a gap or an overlap in octree.bin";
    at = end;
  }
  EXPECT_EQ(at, octreeBytes);

  const lod::OctreeMetadata meta = io::openPotree(dir / "o")->metadata();
  EXPECT_EQ(meta.pointCount, records.size());
  EXPECT_DOUBLE_EQ(meta.spacing, grid.spacing());
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(meta.cube.min[a], grid.cube.min[a], 1e-9);
    EXPECT_NEAR(meta.cube.max[a], grid.cube.max[a], 1e-9);
  }
}

TEST_P(LodPotree, SameBytesFromOneAndTwoThreadsAndOutOfCore) {
  iotest::TempDir dir;
  GenerateOptions g;
  g.points = 250'000;
  g.progress = false;
  io::writeLas(dir / "t.las", generateScene(Scene::Terrain, g), io::LasFlavor::Las12Pf3);
  for (const char* sub : {"a", "b", "c"})
    std::filesystem::create_directory(dir / sub);
  io::LodBuildOptions options;
  options.leafPoints = 5'000;
  options.threads = 1;
  buildTo(dir / "t.las", dir / "a" / "o", options, GetParam());
  options.threads = 2;
  buildTo(dir / "t.las", dir / "b" / "o", options, GetParam());
  options.memoryBytes = 2 << 20; // 2 MiB for 6 MB of records
  const io::PotreeBuildReport spilled = buildTo(dir / "t.las", dir / "c" / "o", options, GetParam());
  EXPECT_TRUE(spilled.build.outOfCore);
  EXPECT_TRUE(sameFiles(dir / "a" / "o", dir / "b" / "o"));
  EXPECT_TRUE(sameFiles(dir / "a" / "o", dir / "c" / "o"));
  for (const auto& entry : std::filesystem::directory_iterator(dir / "c"))
    EXPECT_EQ(entry.path().filename(), "o") << "left behind: " << entry.path();
}

INSTANTIATE_TEST_SUITE_P(Encodings, LodPotree,
                         ::testing::Values(io::PotreeEncoding::Default, io::PotreeEncoding::Brotli),
                         [](const auto& param) {
                           return param.param == io::PotreeEncoding::Default ? "Default" : "Brotli";
                         });

TEST(LodPotreeBuild, FailureLeavesNoFolder) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  iotest::TempDir dir;
  std::filesystem::create_directory(dir / "exists");
  io::LodBuildOptions options;
  EXPECT_THROW(buildTo(data("las/autzen_trim.las"), dir / "exists", options), InputError);
  std::atomic<bool> cancel{true};
  options.cancel = &cancel;
  EXPECT_THROW(buildTo(data("las/autzen_trim.las"), dir / "o", options), Interrupted);
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().filename(), "exists") << "left behind: " << entry.path();
}

} // namespace
