// Potree 2.0 writer and reader: round trips for both encodings (several levels, proxies across chunk
// boundaries), the hierarchy's consistency on disk, lazy chunk loading, PotreeConverter's defects on
// hand-made files that mimic its output, whole-cloud reads and LAS export.
#include <csignal>
#include <fstream>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>
#include <sys/resource.h>

#include "cloud/octree_cloud.h"
#include "io/format_table.h"
#include "io/potree/potree_format.h"
#include "io/potree_test_util.h"
#include "io/writer.h"

using namespace pointrast;
using namespace pointrast::io;
using potreetest::DiskNode;
using potreetest::makeTree;
using potreetest::patchRecord;
using potreetest::readTree;
using potreetest::Tree;
using potreetest::TreeOptions;
using potreetest::walkHierarchy;
using potreetest::writeTree;

namespace {

PotreeWriteOptions writeOptions(PotreeEncoding encoding, int stepSize = 4) {
  PotreeWriteOptions o;
  o.encoding = encoding;
  o.hierarchyStepSize = stepSize;
  return o;
}

nlohmann::json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

void writeJson(const std::filesystem::path& path, const nlohmann::json& j) {
  iotest::writeText(path, j.dump(1));
}

class PotreeRoundTrip : public ::testing::TestWithParam<std::tuple<PotreeEncoding, int>> {};

TEST_P(PotreeRoundTrip, SameNodesAndRecords) {
  const auto [encoding, stepSize] = GetParam();
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 3000, .depth = 5, .color16 = encoding == PotreeEncoding::Brotli});
  writeTree(tree, dir / "octree", writeOptions(encoding, stepSize));

  std::unique_ptr<lod::NodeSource> source = openPotree(dir / "octree");
  const lod::OctreeMetadata& meta = source->metadata();
  EXPECT_EQ(meta.format, encoding == PotreeEncoding::Brotli ? "Potree 2.0 (BROTLI)" : "Potree 2.0 (DEFAULT)");
  EXPECT_EQ(meta.pointCount, tree.points());
  EXPECT_EQ(meta.scale, tree.meta.scale);
  EXPECT_EQ(meta.offset, tree.meta.offset);
  EXPECT_EQ(meta.cube.min, tree.meta.cube.min);
  EXPECT_EQ(meta.cube.max, tree.meta.cube.max);
  EXPECT_EQ(meta.spacing, tree.meta.spacing);
  EXPECT_EQ(meta.depth, 5);
  EXPECT_TRUE(meta.fields.color && meta.fields.intensity && meta.fields.returnNumber &&
              meta.fields.classification && meta.fields.pointSourceId);
  EXPECT_EQ(meta.fields.colorMax > 255, encoding == PotreeEncoding::Brotli);

  const potreetest::ReadBack back = readTree(*source);
  ASSERT_EQ(back.nodes.size(), tree.nodes.size());
  for (const auto& [key, records] : tree.nodes) {
    ASSERT_TRUE(back.nodes.count(key)) << key.potreeName();
    EXPECT_EQ(back.nodes.at(key), records) << key.potreeName(); // same records, same order
    uint8_t mask = 0;
    for (int c = 0; c < 8; ++c)
      mask |= uint8_t(tree.nodes.count(key.child(c)) ? 1u << c : 0u);
    EXPECT_EQ(back.infos.at(key).childMask, mask) << key.potreeName();
  }
  // Tight bounds from the records.
  Bounds expected;
  for (const auto& [key, records] : tree.nodes)
    for (const PointRecord& r : records)
      expected.expand(glm::dvec3(r.x, r.y, r.z) * meta.scale + meta.offset);
  EXPECT_EQ(meta.bounds.min, expected.min);
  EXPECT_EQ(meta.bounds.max, expected.max);
}

INSTANTIATE_TEST_SUITE_P(EncodingsAndChunks, PotreeRoundTrip,
                         ::testing::Combine(::testing::Values(PotreeEncoding::Default,
                                                              PotreeEncoding::Brotli),
                                            ::testing::Values(4, 2, 1)));

TEST(PotreeWriter, HierarchyOnDiskIsConsistent) {
  for (PotreeEncoding encoding : {PotreeEncoding::Default, PotreeEncoding::Brotli}) {
    iotest::TempDir dir;
    const Tree tree = makeTree({.points = 2500, .depth = 5});
    writeTree(tree, dir / "o", writeOptions(encoding, 2));
    const nlohmann::json meta = readJson(dir / "o" / "metadata.json");
    EXPECT_EQ(meta["version"], "2.0");
    EXPECT_EQ(meta["name"], "o");
    EXPECT_EQ(meta["points"], tree.points());
    EXPECT_EQ(meta["encoding"], encoding == PotreeEncoding::Brotli ? "BROTLI" : "DEFAULT");
    EXPECT_EQ(meta["hierarchy"]["stepSize"], 2);
    EXPECT_EQ(meta["hierarchy"]["depth"], 5);
    EXPECT_EQ(meta["generator"], "pointrast");
    std::vector<std::string> names;
    for (const auto& a : meta["attributes"]) {
      names.push_back(a["name"]);
      EXPECT_EQ(a["size"], a["numElements"].get<int>() * a["elementSize"].get<int>()) << a.dump();
    }
    EXPECT_EQ(names, (std::vector<std::string>{"position", "intensity", "return number", "classification",
                                               "point source id", "rgb"}));

    const uint64_t octreeSize = std::filesystem::file_size(dir / "o" / "octree.bin");
    const uint64_t hierarchySize = std::filesystem::file_size(dir / "o" / "hierarchy.bin");
    const std::vector<DiskNode> disk = walkHierarchy(dir / "o");
    std::map<lod::NodeKey, potree::Record> real; // non-proxy records
    uint64_t proxies = 0, bytes = 0, records = 0;
    for (const DiskNode& n : disk) {
      ++records;
      if (n.record.type == potree::kProxy) {
        ++proxies;
        EXPECT_EQ(n.key.level % 2, 0) << "proxies sit on a chunk's last level";
        EXPECT_LE(uint64_t(n.record.byteOffset + n.record.byteSize), hierarchySize);
        continue;
      }
      EXPECT_TRUE(real.emplace(n.key, n.record).second) << n.key.potreeName();
      const auto& points = tree.nodes.at(n.key);
      EXPECT_EQ(n.record.pointCount, points.size());
      EXPECT_EQ(n.record.type, n.record.childMask ? potree::kNormal : potree::kLeaf);
      EXPECT_LE(uint64_t(n.record.byteOffset + n.record.byteSize), octreeSize);
      if (encoding == PotreeEncoding::Default) {
        EXPECT_EQ(uint64_t(n.record.byteSize), points.size() * 24u); // 12 + 2 + 1 + 1 + 2 + 6 bytes
      }
      bytes += uint64_t(n.record.byteSize);
      for (int c = 0; c < 8; ++c)
        EXPECT_EQ(bool(n.record.childMask & (1 << c)), tree.nodes.count(n.key.child(c)) == 1)
            << n.key.potreeName();
    }
    EXPECT_EQ(real.size(), tree.nodes.size());
    EXPECT_GT(proxies, 0u);
    EXPECT_EQ(bytes, octreeSize) << "node byte ranges tile octree.bin";
    EXPECT_EQ(records * potree::kRecordBytes, hierarchySize) << "chunks tile hierarchy.bin";
    // Ranges do not overlap.
    std::vector<std::pair<int64_t, int64_t>> ranges;
    for (const auto& [key, r] : real)
      ranges.push_back({r.byteOffset, r.byteOffset + r.byteSize});
    std::sort(ranges.begin(), ranges.end());
    for (size_t i = 1; i < ranges.size(); ++i)
      EXPECT_LE(ranges[i - 1].second, ranges[i].first);
  }
}

TEST(PotreeWriter, RecordsAreBreadthFirstAsThePotreeViewerAssignsThem) {
  iotest::TempDir dir;
  writeTree(makeTree({.points = 800, .depth = 3}), dir / "o", writeOptions(PotreeEncoding::Default));
  const std::vector<DiskNode> disk = walkHierarchy(dir / "o");
  ASSERT_FALSE(disk.empty());
  EXPECT_EQ(disk[0].key, lod::NodeKey{});
  for (size_t i = 1; i < disk.size(); ++i) {
    const std::string a = disk[i - 1].key.potreeName(), b = disk[i].key.potreeName();
    EXPECT_TRUE(a.size() < b.size() || (a.size() == b.size() && a < b)) << a << " before " << b;
  }
}

TEST(PotreeWriter, SameBytesEveryTimeAndFromParallelEncoding) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 1500, .depth = 4});
  for (PotreeEncoding encoding : {PotreeEncoding::Default, PotreeEncoding::Brotli}) {
    PotreeWriteOptions o = writeOptions(encoding, 2);
    o.name = "same";
    o.description = "written three times";
    writeTree(tree, dir / "a", o);
    writeTree(tree, dir / "b", o);
    {
      PotreeWriter writer(dir / "c", tree.meta, o);
      std::vector<const std::pair<const lod::NodeKey, std::vector<PointRecord>>*> order;
      for (const auto& entry : tree.nodes)
        order.push_back(&entry);
      std::vector<PotreeEncodedNode> encoded(order.size());
      std::vector<std::thread> threads;
      for (size_t t = 0; t < 3; ++t)
        threads.emplace_back([&, t] {
          for (size_t i = t; i < order.size(); i += 3)
            encoded[i] = writer.encodeNode(order[i]->second.data(), order[i]->second.size());
        });
      for (auto& th : threads)
        th.join();
      for (size_t i = 0; i < order.size(); ++i)
        writer.writeEncoded(order[i]->first, std::move(encoded[i]));
      writer.commit();
    }
    for (const char* file : {"metadata.json", "hierarchy.bin", "octree.bin"}) {
      const auto a = iotest::readBytes(dir / "a" / file);
      EXPECT_TRUE(a == iotest::readBytes(dir / "b" / file)) << file;
      EXPECT_TRUE(a == iotest::readBytes(dir / "c" / file)) << file;
    }
    std::filesystem::remove_all(dir / "a");
    std::filesystem::remove_all(dir / "b");
    std::filesystem::remove_all(dir / "c");
  }
}

TEST(PotreeWriter, FolderAppearsOnlyAtCommit) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 300, .depth = 2});
  {
    PotreeWriter writer(dir / "o", tree.meta, writeOptions(PotreeEncoding::Default));
    EXPECT_TRUE(std::filesystem::is_directory(writer.workingDir()));
    EXPECT_EQ(writer.workingDir().parent_path(), dir.path());
    for (const auto& [key, records] : tree.nodes)
      writer.writeNode(key, records.data(), records.size());
    EXPECT_GT(writer.bytesWritten(), 0u);
    EXPECT_FALSE(std::filesystem::exists(dir / "o"));
  } // no commit
  EXPECT_FALSE(std::filesystem::exists(dir / "o"));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << "the temporary folder is removed";

  writeTree(tree, dir / "o", writeOptions(PotreeEncoding::Default));
  EXPECT_TRUE(std::filesystem::exists(dir / "o" / "metadata.json"));
  try {
    PotreeWriter again(dir / "o", tree.meta, writeOptions(PotreeEncoding::Default));
    FAIL() << "an existing folder must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("already exists"), std::string::npos) << e.what();
  }
  EXPECT_THROW(PotreeWriter(dir / "missing" / "o", tree.meta, writeOptions(PotreeEncoding::Default)),
               InputError);
}

TEST(PotreeWriter, WriteErrorNamesTheFolderAndLeavesNothing) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 20000, .depth = 3});
  // A file size limit makes writes fail as a full disk does (EFBIG instead of ENOSPC).
  struct rlimit old {};
  getrlimit(RLIMIT_FSIZE, &old);
  auto oldHandler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = old;
  small.rlim_cur = 64 << 10;
  setrlimit(RLIMIT_FSIZE, &small);
  std::string message;
  try {
    writeTree(tree, dir / "o", writeOptions(PotreeEncoding::Default));
  } catch (const InputError& e) {
    message = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, oldHandler);
  EXPECT_NE(message.find((dir / "o").string() + ": cannot write"), std::string::npos) << message;
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(PotreeWriter, EmptyOctreeIsAnEmptyRoot) {
  iotest::TempDir dir;
  Tree tree = makeTree({.points = 0});
  { PotreeWriter(dir / "o", tree.meta, writeOptions(PotreeEncoding::Brotli)).commit(); }
  auto source = openPotree(dir / "o");
  EXPECT_EQ(source->root().pointCount, 0u);
  EXPECT_EQ(source->root().childMask, 0u);
  EXPECT_TRUE(source->readNode(source->root()).empty());
  EXPECT_EQ(readCloud(dir / "o", iotest::quiet()).size(), 0u);
}

TEST(PotreeWriter, RefusesBrotliNodesOfIdenticalPoints) {
  iotest::TempDir dir;
  Tree tree = makeTree({.points = 0});
  std::vector<PointRecord> same(200000);
  {
    PotreeWriter writer(dir / "b", tree.meta, writeOptions(PotreeEncoding::Brotli));
    EXPECT_THROW(writer.writeNode(lod::NodeKey{}, same.data(), same.size()), InputError);
  }
  PotreeWriter writer(dir / "d", tree.meta, writeOptions(PotreeEncoding::Default));
  writer.writeNode(lod::NodeKey{}, same.data(), same.size());
  writer.commit();
  EXPECT_EQ(openPotree(dir / "d")->readNode({lod::NodeKey{}, 200000, 0}), same);
}

TEST(PotreeReader, LoadsAChunkOnlyWhenAskedFor) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 3000, .depth = 3});
  writeTree(tree, dir / "o", writeOptions(PotreeEncoding::Default, 1));
  // Damage the chunk of r0 (a proxy in the root chunk): everything else must still read.
  const std::vector<DiskNode> disk = walkHierarchy(dir / "o");
  int64_t chunkOfR0 = -1;
  for (const DiskNode& n : disk)
    if (n.key == lod::NodeKey{1, 0, 0, 0} && n.record.type == potree::kProxy) chunkOfR0 = n.record.byteOffset;
  ASSERT_GE(chunkOfR0, 0);
  std::vector<uint8_t> bytes = iotest::readBytes(dir / "o" / "hierarchy.bin");
  bytes[size_t(chunkOfR0)] = 9; // record type 9
  iotest::writeBytes(dir / "o" / "hierarchy.bin", bytes);

  auto source = openPotree(dir / "o");
  const lod::NodeInfo root = source->root();
  const std::vector<lod::NodeInfo> level1 = source->children(root);
  ASSERT_EQ(level1.size(), 8u);
  EXPECT_EQ(level1[0].key, (lod::NodeKey{1, 0, 0, 0}));
  EXPECT_EQ(level1[0].pointCount, tree.nodes.at(level1[0].key).size()); // from the proxy record
  EXPECT_EQ(source->readNode(level1[1]), tree.nodes.at(level1[1].key));
  EXPECT_FALSE(source->children(level1[1]).empty());
  try {
    source->children(level1[0]);
    FAIL() << "r0's chunk is damaged";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("hierarchy.bin"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("type 9"), std::string::npos) << e.what();
  }
  // Asked again, the same sentence.
  try {
    source->readNode(level1[0]);
    FAIL() << "r0's chunk is damaged";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("type 9"), std::string::npos) << e.what();
  }
}

TEST(PotreeReader, SeveralThreadsReadTheSameSource) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 4000, .depth = 4});
  writeTree(tree, dir / "o", writeOptions(PotreeEncoding::Brotli, 1));
  auto source = openPotree(dir / "o");
  std::vector<potreetest::ReadBack> results(4);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < results.size(); ++t)
    threads.emplace_back([&, t] { results[t] = readTree(*source); });
  for (auto& th : threads)
    th.join();
  for (const auto& r : results)
    EXPECT_EQ(r.nodes, tree.nodes);
}

TEST(PotreeReader, FolderOrMetadataJson) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 500, .depth = 2});
  writeTree(tree, dir / "o", writeOptions(PotreeEncoding::Default));
  EXPECT_TRUE(looksLikePotree(dir / "o"));
  EXPECT_TRUE(looksLikePotree(dir / "o" / "metadata.json"));
  EXPECT_FALSE(looksLikePotree(dir / "o" / "octree.bin"));
  EXPECT_FALSE(looksLikePotree(dir.path()));
  EXPECT_STREQ(detectFormat(dir / "o")->name, "Potree 2.0");
  EXPECT_EQ(openPotree(dir / "o" / "metadata.json")->metadata().pointCount, 500u);
  EXPECT_THROW(openPotree(dir / "o" / "octree.bin"), InputError);
}

// ---- PotreeConverter's output, mimicked by hand --------------------------------------------------

// Writes `tree` as PotreeConverter would store it: its BROTLI writer stores every integer one quantum
// high; there is no "generator" field.
void writeLikePotreeConverter(const Tree& tree, const std::filesystem::path& dir, PotreeEncoding encoding,
                              int stepSize = 4) {
  Tree stored = tree;
  if (encoding == PotreeEncoding::Brotli)
    for (auto& [key, records] : stored.nodes)
      for (PointRecord& r : records) {
        ++r.x;
        ++r.y;
        ++r.z;
      }
  writeTree(stored, dir, writeOptions(encoding, stepSize));
  nlohmann::json meta = readJson(dir / "metadata.json");
  meta.erase("generator");
  writeJson(dir / "metadata.json", meta);
}

TEST(PotreeConverterFiles, BrotliShiftIsUndoneExactly) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 2000, .depth = 3, .color16 = true});
  writeLikePotreeConverter(tree, dir / "pc", PotreeEncoding::Brotli);
  EXPECT_FALSE(probePotree(dir / "pc").fromPointrast);
  EXPECT_EQ(readTree(*openPotree(dir / "pc")).nodes, tree.nodes);

  // The generator field decides: the same bytes marked as pointrast's are read as they are.
  nlohmann::json meta = readJson(dir / "pc" / "metadata.json");
  meta["generator"] = "pointrast";
  writeJson(dir / "pc" / "metadata.json", meta);
  const auto asOurs = readTree(*openPotree(dir / "pc")).nodes;
  EXPECT_EQ(asOurs.at(lod::NodeKey{}).at(0).x, tree.nodes.at(lod::NodeKey{}).at(0).x + 1);
}

TEST(PotreeConverterFiles, DefaultIsReadAsStoredAndInfoWarns) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 1000, .depth = 3});
  writeLikePotreeConverter(tree, dir / "pc", PotreeEncoding::Default);
  EXPECT_EQ(readTree(*openPotree(dir / "pc")).nodes, tree.nodes);
  const FileInfo info = probeFile(dir / "pc");
  EXPECT_NE(info.formatDetail.find("PotreeConverter"), std::string::npos) << info.formatDetail;
  bool warned = false;
  for (const auto& [key, value] : info.extra)
    warned |= key == "coordinates" && value.find("one quantum low") != std::string::npos;
  EXPECT_TRUE(warned);
}

// Sets the byte size of `key`'s real record to 0: a node that claims points but holds no bytes.
void zeroByteSize(const std::filesystem::path& dir, const lod::NodeKey& key) {
  patchRecord(dir, key, false, [](potree::Record& r) { r.byteSize = 0; });
}

// Read as empty, such a node would vanish from a conversion with exit code 0; it is damage whoever wrote
// the folder, and the error names it.
TEST(PotreeConverterFiles, NodesWithPointsButNoBytesAreAnError) {
  for (PotreeEncoding encoding : {PotreeEncoding::Default, PotreeEncoding::Brotli}) {
    iotest::TempDir dir;
    Tree tree = makeTree({.points = 1500, .depth = 3});
    const lod::NodeKey inner{1, 1, 0, 1};
    ASSERT_FALSE(tree.nodes.at(inner).empty());
    writeLikePotreeConverter(tree, dir / "pc", encoding);
    writeTree(tree, dir / "ours", writeOptions(encoding));
    for (const char* folder : {"pc", "ours"}) {
      zeroByteSize(dir / folder, inner);
      std::string message;
      try {
        readTree(*openPotree(dir / folder));
      } catch (const InputError& e) {
        message = e.what();
      }
      EXPECT_NE(message.find("node r5"), std::string::npos) << folder << ": " << message;
      EXPECT_NE(message.find("claims"), std::string::npos) << folder << ": " << message;
    }
  }
}

TEST(PotreeConverterFiles, ProxyWithoutChildMaskIsResolvedWhenListed) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 2000, .depth = 3});
  writeLikePotreeConverter(tree, dir / "pc", PotreeEncoding::Default, 1);
  std::vector<uint8_t> bytes = iotest::readBytes(dir / "pc" / "hierarchy.bin");
  const nlohmann::json meta = readJson(dir / "pc" / "metadata.json");
  const uint64_t first = meta["hierarchy"]["firstChunkSize"];
  int cleared = 0;
  for (uint64_t at = 0; at < first; at += potree::kRecordBytes)
    if (bytes[at] == potree::kProxy) {
      bytes[at + 1] = 0;
      ++cleared;
    }
  ASSERT_GT(cleared, 0);
  iotest::writeBytes(dir / "pc" / "hierarchy.bin", bytes);
  EXPECT_EQ(readTree(*openPotree(dir / "pc")).nodes, tree.nodes);
}

// ---- whole clouds and exports ----------------------------------------------------------------------

TEST(PotreeCloud, ReadCloudHoldsEveryPointWithTheLasColorRule) {
  for (bool color16 : {false, true}) {
    iotest::TempDir dir;
    const Tree tree = makeTree({.points = 3000, .depth = 4, .color16 = color16});
    writeTree(tree, dir / "o", writeOptions(PotreeEncoding::Brotli, 2));
    const PointCloud cloud = readCloud(dir / "o", iotest::quiet());
    ASSERT_EQ(cloud.size(), tree.points());
    EXPECT_EQ(cloud.scale, tree.meta.scale);
    EXPECT_EQ(cloud.offset, tree.meta.offset);
    std::multiset<std::tuple<int32_t, int32_t, int32_t, uint32_t, uint16_t, uint8_t, uint8_t>> expected, got;
    const int shift = color16 ? 8 : 0;
    for (const auto& [key, records] : tree.nodes)
      for (const PointRecord& r : records)
        expected.insert({r.x, r.y, r.z, packRgba(r.rgb[0] >> shift, r.rgb[1] >> shift, r.rgb[2] >> shift),
                         r.intensity, r.classification, r.returnNumber});
    for (uint64_t i = 0; i < cloud.size(); ++i)
      got.insert({cloud.positions[3 * i], cloud.positions[3 * i + 1], cloud.positions[3 * i + 2],
                  cloud.colors[i], cloud.intensity[i], cloud.classification[i], cloud.returnNumber[i]});
    EXPECT_EQ(got, expected);

    // metadata.json's color range is only the first guess: a wrong one does not change the colors.
    nlohmann::json meta = readJson(dir / "o" / "metadata.json");
    for (auto& a : meta["attributes"])
      if (a["name"] == "rgb")
        a["max"] = color16 ? nlohmann::json{255, 255, 255} : nlohmann::json{65535, 65535, 65535};
    writeJson(dir / "o" / "metadata.json", meta);
    EXPECT_EQ(readCloud(dir / "o" / "metadata.json", iotest::quiet()).colors, cloud.colors);
  }
}

TEST(PotreeCloud, ExportToLasIsExact) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 2500, .depth = 4, .color16 = true});
  writeTree(tree, dir / "o", writeOptions(PotreeEncoding::Default, 2));
  auto source = openPotree(dir / "o");
  EXPECT_EQ(writeLasFromOctree(dir / "all.las", *source, LasFlavor::Las14Pf7, false), tree.points());
  EXPECT_FALSE(std::filesystem::exists(dir / "all.las.partial"));
  // Records in forEachNode order, field by field (PF7: 36-byte records after a 375-byte header).
  std::vector<PointRecord> expected;
  lod::forEachNode(*source, [&](const lod::NodeInfo& node) {
    const auto& r = tree.nodes.at(node.key);
    expected.insert(expected.end(), r.begin(), r.end());
    return true;
  });
  const std::vector<uint8_t> bytes = iotest::readBytes(dir / "all.las");
  ASSERT_EQ(bytes.size(), 375u + 36u * expected.size());
  double scale[3], offset[3];
  std::memcpy(scale, bytes.data() + 131, 24);
  std::memcpy(offset, bytes.data() + 155, 24);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(scale[a], tree.meta.scale[a]);
    EXPECT_EQ(offset[a], tree.meta.offset[a]);
  }
  for (size_t i = 0; i < expected.size(); ++i) {
    const uint8_t* p = bytes.data() + 375 + 36 * i;
    PointRecord r;
    std::memcpy(&r.x, p, 4);
    std::memcpy(&r.y, p + 4, 4);
    std::memcpy(&r.z, p + 8, 4);
    std::memcpy(&r.intensity, p + 12, 2);
    r.returnNumber = p[14] & 0x0F;
    r.classification = p[16];
    std::memcpy(&r.pointSourceId, p + 20, 2);
    std::memcpy(r.rgb, p + 30, 6);
    ASSERT_EQ(r, expected[i]) << "point " << i;
  }
  const PointCloud las = readCloud(dir / "all.las", iotest::quiet());
  EXPECT_EQ(las.size(), expected.size());
}

TEST(PotreeCloud, ProbeDescribesTheOctree) {
  iotest::TempDir dir;
  const Tree tree = makeTree({.points = 1200, .depth = 3});
  writeTree(tree, dir / "o", writeOptions(PotreeEncoding::Brotli, 2));
  const FileInfo info = probeFile(dir / "o");
  EXPECT_STREQ(info.format->name, "Potree 2.0");
  EXPECT_EQ(info.pointCount, tree.points());
  EXPECT_TRUE(info.hasColor);
  EXPECT_EQ(info.colorBits, 8);
  std::map<std::string, std::string> extra(info.extra.begin(), info.extra.end());
  EXPECT_EQ(extra["nodes"], std::to_string(tree.nodes.size()));
  EXPECT_EQ(extra["depth"], "3 levels below the root");
  EXPECT_EQ(extra["encoding"], "BROTLI");
  EXPECT_NE(extra["attributes"].find("rgb (uint16 x3)"), std::string::npos) << extra["attributes"];
  EXPECT_NE(info.formatDetail.find("written by pointrast"), std::string::npos) << info.formatDetail;
}

} // namespace
