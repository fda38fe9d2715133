// Hand-built octrees for the Potree tests: random records spread over the levels of a tree (every point
// inside its node's cube, every node's parent present), written with PotreeWriter and read back whole.
#pragma once

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cloud/octree.h"
#include "io/io_test_util.h"
#include "io/potree/potree.h"
#include "io/potree/potree_format.h"

namespace potreetest {

using pointrast::PointRecord;
using pointrast::lod::NodeKey;

struct Tree {
  pointrast::lod::OctreeMetadata meta;
  std::map<NodeKey, std::vector<PointRecord>> nodes; // every node of the tree, possibly empty
  uint64_t points() const {
    uint64_t n = 0;
    for (const auto& [key, records] : nodes)
      n += records.size();
    return n;
  }
};

struct TreeOptions {
  uint64_t points = 2000;
  int depth = 4;        // deepest level
  bool color16 = false; // 16-bit colors (values above 255), else 0..255
  int32_t edgeQuanta = 100000;
  uint64_t seed = 3;
};

// Points uniform in the cube (scale 1 mm, cube edge edgeQuanta); each goes to a level drawn at random
// (deeper levels more often, as in a real octree) and to the cell of that level that contains it.
inline Tree makeTree(const TreeOptions& o = {}) {
  Tree t;
  t.meta.scale = glm::dvec3(0.001);
  t.meta.offset = glm::dvec3(637000.0, 849000.0, 400.0);
  t.meta.cube.min = t.meta.offset;
  t.meta.cube.max = t.meta.offset + glm::dvec3(o.edgeQuanta * 0.001);
  t.meta.spacing = o.edgeQuanta * 0.001 / 128.0;
  t.meta.fields.color = t.meta.fields.intensity = t.meta.fields.returnNumber = true;
  t.meta.fields.classification = t.meta.fields.pointSourceId = true;
  t.meta.fields.colorMax = o.color16 ? 65535 : 255;
  iotest::Lcg rng(o.seed);
  t.nodes[NodeKey{}];
  for (uint64_t i = 0; i < o.points; ++i) {
    PointRecord r;
    r.x = int32_t(rng.next() % uint32_t(o.edgeQuanta));
    r.y = int32_t(rng.next() % uint32_t(o.edgeQuanta));
    r.z = int32_t(rng.next() % uint32_t(o.edgeQuanta));
    for (auto& c : r.rgb)
      c = uint16_t(o.color16 ? rng.next() & 0xFFFF : rng.next() & 0xFF);
    r.intensity = uint16_t(rng.next());
    r.returnNumber = uint8_t(1 + rng.next() % 5);
    r.classification = uint8_t(rng.next() % 40);
    r.pointSourceId = uint16_t(rng.next());
    int level = 0;
    while (level < o.depth && rng.next() % 3 != 0)
      ++level;
    NodeKey key;
    key.level = level;
    const int64_t cells = int64_t(1) << level;
    key.x = int32_t(int64_t(r.x) * cells / o.edgeQuanta);
    key.y = int32_t(int64_t(r.y) * cells / o.edgeQuanta);
    key.z = int32_t(int64_t(r.z) * cells / o.edgeQuanta);
    t.nodes[key].push_back(r);
    for (NodeKey p = key; p.level > 0;) {
      p = p.parent();
      t.nodes[p];
    }
  }
  return t;
}

inline void writeTree(const Tree& t, const std::filesystem::path& dir,
                      const pointrast::io::PotreeWriteOptions& o) {
  pointrast::io::PotreeWriter writer(dir, t.meta, o);
  for (const auto& [key, records] : t.nodes)
    writer.writeNode(key, records.data(), records.size());
  writer.commit();
}

// Every node of a source with its records, read through the NodeSource interface.
struct ReadBack {
  std::map<NodeKey, std::vector<PointRecord>> nodes;
  std::map<NodeKey, pointrast::lod::NodeInfo> infos;
};
inline ReadBack readTree(pointrast::lod::NodeSource& source) {
  ReadBack out;
  pointrast::lod::forEachNode(source, [&](const pointrast::lod::NodeInfo& node) {
    EXPECT_EQ(out.nodes.count(node.key), 0u) << node.key.potreeName() << " listed twice";
    out.nodes[node.key] = source.readNode(node);
    out.infos[node.key] = node;
    EXPECT_EQ(out.nodes[node.key].size(), node.pointCount) << node.key.potreeName();
    return true;
  });
  return out;
}

// Every record of a hierarchy.bin with its byte position, chunk by chunk from the first, following
// proxies.
struct DiskNode {
  NodeKey key;
  pointrast::io::potree::Record record;
  uint64_t at = 0;    // byte position of the record in hierarchy.bin
  uint64_t chunk = 0; // byte position of the chunk holding it
};
inline std::vector<DiskNode> walkHierarchy(const std::filesystem::path& dir) {
  std::ifstream in(dir / "metadata.json");
  const uint64_t first = nlohmann::json::parse(in)["hierarchy"]["firstChunkSize"];
  const std::vector<uint8_t> bytes = iotest::readBytes(dir / "hierarchy.bin");
  namespace potree = pointrast::io::potree;
  std::vector<DiskNode> out;
  std::vector<std::pair<NodeKey, std::pair<uint64_t, uint64_t>>> chunks{{NodeKey{}, {0, first}}};
  for (size_t c = 0; c < chunks.size(); ++c) {
    const auto [root, range] = chunks[c];
    if (range.first > bytes.size() || range.second > bytes.size() - range.first)
      throw std::runtime_error("walkHierarchy: a chunk outside hierarchy.bin");
    const auto records = potree::parseChunk(bytes.data() + range.first, range.second, root, "test");
    for (size_t i = 0; i < records.size(); ++i) {
      out.push_back({records[i].key, records[i].record, range.first + i * potree::kRecordBytes, range.first});
      if (records[i].record.type == potree::kProxy)
        chunks.push_back(
            {records[i].key, {uint64_t(records[i].record.byteOffset), uint64_t(records[i].record.byteSize)}});
    }
  }
  return out;
}

// Rewrites the record of `key` (its proxy record when proxy is true, else its real one) through edit.
template <class Edit>
void patchRecord(const std::filesystem::path& dir, const NodeKey& key, bool proxy, Edit edit) {
  namespace potree = pointrast::io::potree;
  std::vector<uint8_t> bytes = iotest::readBytes(dir / "hierarchy.bin");
  for (const DiskNode& n : walkHierarchy(dir)) {
    if (n.key != key || (n.record.type == potree::kProxy) != proxy) continue;
    potree::Record r = n.record;
    edit(r);
    potree::storeRecord(bytes.data() + n.at, r);
    iotest::writeBytes(dir / "hierarchy.bin", bytes);
    return;
  }
  ADD_FAILURE() << "no " << (proxy ? "proxy" : "real") << " record of " << key.potreeName();
}

} // namespace potreetest
