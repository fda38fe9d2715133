// Hand-built octrees for the Potree tests: random records spread over the levels of a tree (every point
// inside its node's cube, every node's parent present), written with PotreeWriter and read back whole.
#pragma once

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cloud/octree.h"
#include "io/io_test_util.h"
#include "io/potree.h"

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

} // namespace potreetest
