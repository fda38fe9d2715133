// COPC as an LOD source: shared/data/laz/lone-star.copc.laz node by node against the sequential decode,
// and hostile hierarchies made from it (cycles, entries outside the file or their subtree, lying counts).
#include <map>
#include <thread>

#include "io/copc_ept/copc.h"
#include "io/io_test_util.h"
#include "io/las/las_records.h"
#include "io/las/laz_format.h"
#include "io/las/laz_reader.h"

using pointrast::InputError;
using pointrast::PointRecord;
using namespace pointrast::io;
using iotest::data;
using pointrast::lod::NodeInfo;
using pointrast::lod::NodeKey;

namespace {

const char* kCopc = "laz/lone-star.copc.laz";

std::vector<NodeInfo> allNodes(pointrast::lod::NodeSource& source) {
  std::vector<NodeInfo> nodes;
  pointrast::lod::forEachNode(source, [&](const NodeInfo& n) {
    nodes.push_back(n);
    return true;
  });
  return nodes;
}

TEST(Copc, MetadataFromTheInfoVlr) {
  POINTRAST_REQUIRE_DATA("laz/autzen_trim.laz");
  const auto source = openCopc(data(kCopc));
  const auto& m = source->metadata();
  EXPECT_EQ(m.format, "COPC 1.0");
  EXPECT_EQ(m.pointCount, 518862u);
  EXPECT_NEAR(m.cube.max.x - m.cube.min.x, 2 * 20.379875000100583, 1e-9);
  EXPECT_NEAR(m.cube.min.x + 20.379875000100583, 515388.9821250001, 1e-6);
  EXPECT_NEAR(m.spacing, 0.3184355468765716, 1e-12);
  EXPECT_EQ(m.scale, glm::dvec3(0.00025));
  EXPECT_FALSE(m.fields.color);
  EXPECT_TRUE(looksLikeCopc(data(kCopc)));
  EXPECT_FALSE(looksLikeCopc(data("laz/autzen_trim.laz")));
  EXPECT_THROW(openCopc(data("laz/autzen_trim.laz")), InputError);
}

TEST(Copc, EachNodeDecodedAloneEqualsTheSequentialDecode) {
  POINTRAST_REQUIRE_DATA();
  const auto source = openCopc(data(kCopc));
  const std::vector<uint8_t> records = readLazRecords(data(kCopc), 1);
  detail::InputFile file(data(kCopc));
  const laz::LazFile laz = laz::openLaz(file);
  const std::vector<NodeInfo> nodes = allNodes(*source);
  EXPECT_EQ(nodes.size(), 15u);
  uint64_t total = 0;
  for (const NodeInfo& node : nodes) {
    total += node.pointCount;
    if (node.pointCount == 0) continue;
    // The node's chunk in the chunk table: the one of the same size and count.
    const laz::Chunk* chunk = nullptr;
    for (const laz::Chunk& c : laz.chunks)
      if (c.bytes == source->nodeBytes(node) && c.pointCount == node.pointCount) {
        ASSERT_EQ(chunk, nullptr) << "two chunks look alike";
        chunk = &c;
      }
    ASSERT_NE(chunk, nullptr);
    const std::vector<PointRecord> got = source->readNode(node);
    ASSERT_EQ(got.size(), node.pointCount);
    for (size_t k = 0; k < got.size(); ++k)
      ASSERT_EQ(got[k], detail::toPointRecord(records.data() + (chunk->firstPoint + k) * 30, true, -1))
          << node.key.potreeName() << " point " << k;
    // Every point lies in its node's cube (to the scale step).
    const auto cube = source->metadata().nodeCube(node.key);
    const auto& m = source->metadata();
    for (size_t k = 0; k < got.size(); k += 101) {
      const double x = got[k].x * m.scale.x + m.offset.x;
      EXPECT_GE(x, cube.min.x - m.scale.x);
      EXPECT_LE(x, cube.max.x + m.scale.x);
    }
  }
  EXPECT_EQ(total, 518862u);
}

TEST(Copc, NodesReadFromManyThreadsAgree) {
  POINTRAST_REQUIRE_DATA();
  const auto source = openCopc(data(kCopc));
  const std::vector<NodeInfo> nodes = allNodes(*source);
  std::vector<std::vector<PointRecord>> sequential;
  for (const NodeInfo& n : nodes)
    sequential.push_back(source->readNode(n));
  const auto fresh = openCopc(data(kCopc)); // hierarchy and decoders used from threads from the start
  const std::vector<NodeInfo> again = allNodes(*fresh);
  std::vector<std::vector<PointRecord>> parallel(again.size());
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (size_t i = size_t(t); i < again.size(); i += 4)
        parallel[i] = fresh->readNode(again[i]);
    });
  for (auto& t : threads)
    t.join();
  EXPECT_EQ(parallel, sequential);
}

// ---- hostile hierarchies --------------------------------------------------------------------------------

struct CopcBytes {
  std::vector<uint8_t> bytes;
  uint64_t rootOffset = 0, rootSize = 0;
  // Entry i of the root page.
  uint8_t* entry(size_t i) { return bytes.data() + rootOffset + 32 * i; }
  size_t entries() const { return rootSize / 32; }
};

CopcBytes loadCopc() {
  CopcBytes c;
  c.bytes = iotest::readBytes(data(kCopc));
  // The info VLR is the first VLR (COPC requires it): payload at 375 + 54.
  std::memcpy(&c.rootOffset, c.bytes.data() + 375 + 54 + 40, 8);
  std::memcpy(&c.rootSize, c.bytes.data() + 375 + 54 + 48, 8);
  return c;
}

template <class T> void put(uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof v);
}

int32_t level(const uint8_t* e) {
  int32_t l;
  std::memcpy(&l, e, 4);
  return l;
}

// Opens the file and walks and reads every node; expects one InputError naming the file with `words`.
void expectHierarchyRefused(const std::vector<uint8_t>& bytes, const std::string& words) {
  iotest::TempDir dir;
  const auto path = dir / "hostile.copc.laz";
  iotest::writeBytes(path, bytes);
  try {
    const auto source = openCopc(path);
    pointrast::lod::forEachNode(*source, [&](const NodeInfo& n) {
      source->readNode(n);
      return true;
    });
    ADD_FAILURE() << "expected an InputError about: " << words;
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("hostile.copc.laz"), std::string::npos) << m;
    EXPECT_NE(m.find(words), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

// The first entry of the root page at the given level.
size_t entryAtLevel(CopcBytes& c, int32_t want) {
  for (size_t i = 0; i < c.entries(); ++i)
    if (level(c.entry(i)) == want) return i;
  ADD_FAILURE() << "no entry at level " << want;
  return 0;
}

TEST(Copc, HierarchyCyclesAreRefused) {
  POINTRAST_REQUIRE_DATA();
  CopcBytes c = loadCopc();
  // A level-1 node's entry turned into a reference to the root page itself.
  uint8_t* e = c.entry(entryAtLevel(c, 1));
  put<uint64_t>(e + 16, c.rootOffset);
  put<int32_t>(e + 24, int32_t(c.rootSize));
  put<int32_t>(e + 28, -1);
  expectHierarchyRefused(c.bytes, "referenced twice (a cycle)");
}

TEST(Copc, HierarchyEntriesOutOfRangeAreRefused) {
  POINTRAST_REQUIRE_DATA();
  {
    CopcBytes c = loadCopc();
    put<uint64_t>(c.entry(entryAtLevel(c, 1)) + 16, uint64_t(c.bytes.size()) + 1000);
    expectHierarchyRefused(c.bytes, "lies outside the point data");
  }
  {
    CopcBytes c = loadCopc();
    put<int32_t>(c.entry(entryAtLevel(c, 2)) + 24, 0x7FFFFFFF);
    expectHierarchyRefused(c.bytes, "lies outside the point data");
  }
  {
    CopcBytes c = loadCopc();
    put<int32_t>(c.entry(entryAtLevel(c, 2)), 40);
    expectHierarchyRefused(c.bytes, "has level 40");
  }
  {
    CopcBytes c = loadCopc();
    put<int32_t>(c.entry(entryAtLevel(c, 1)) + 4, 2); // x = 2 at level 1
    expectHierarchyRefused(c.bytes, "outside its level");
  }
  {
    CopcBytes c = loadCopc();
    put<int32_t>(c.entry(entryAtLevel(c, 1)) + 28, -7);
    expectHierarchyRefused(c.bytes, "point count of -7");
  }
  {
    CopcBytes c = loadCopc();
    uint8_t* e = c.entry(entryAtLevel(c, 1));
    put<int32_t>(e + 24, 33); // a page of 33 bytes
    put<int32_t>(e + 28, -1);
    expectHierarchyRefused(c.bytes, "not a multiple");
  }
  {
    // A subtree page holding one entry of the root page that is not in its subtree.
    CopcBytes c = loadCopc();
    const size_t l1 = entryAtLevel(c, 1), l2 = entryAtLevel(c, 2);
    NodeKey k1, k2;
    std::memcpy(&k1, c.entry(l1), 16);
    std::memcpy(&k2, c.entry(l2), 16);
    ASSERT_FALSE((k2.x >> 1) == k1.x && (k2.y >> 1) == k1.y && (k2.z >> 1) == k1.z) << "pick another pair";
    uint8_t* e = c.entry(l1);
    put<uint64_t>(e + 16, c.rootOffset + 32 * l2);
    put<int32_t>(e + 24, 32);
    put<int32_t>(e + 28, -1);
    expectHierarchyRefused(c.bytes, "outside its subtree");
  }
  {
    CopcBytes c = loadCopc();
    std::memcpy(c.entry(entryAtLevel(c, 2)), c.entry(entryAtLevel(c, 1)), 16); // the same key twice
    expectHierarchyRefused(c.bytes, "listed twice");
  }
  {
    // The root page's size in the info VLR past the end of the file.
    CopcBytes c = loadCopc();
    put<uint64_t>(c.bytes.data() + 375 + 54 + 48, uint64_t(1) << 40);
    expectHierarchyRefused(c.bytes, "lies outside the file");
  }
}

TEST(Copc, CountsThatLieAreRefused) {
  POINTRAST_REQUIRE_DATA();
  CopcBytes c = loadCopc();
  uint8_t* e = c.entry(entryAtLevel(c, 2));
  int32_t count;
  std::memcpy(&count, e + 28, 4);
  put<int32_t>(e + 28, count + 1);
  expectHierarchyRefused(c.bytes, "counts " + std::to_string(count) + " points itself");
  put<int32_t>(e + 28, 0x7FFFFFF0); // billions claimed: refused without allocating for them
  expectHierarchyRefused(c.bytes, "counts " + std::to_string(count) + " points itself");
}

} // namespace
