// NodeSources for the LOD tests: an in-memory additive octree built from a cloud by a simple rule (a node
// past `leafLimit` points keeps the first point of each cell of a grid of `cellsPerEdge` cells per edge and
// hands the rest to its children), or filled by hand; nodes can be marked damaged, so that reading their
// points or their children throws as a broken file would.
#pragma once

#include <atomic>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "base/error.h"
#include "cloud/octree.h"

namespace pointrast::test {

class MemoryOctree : public lod::NodeSource {
public:
  lod::OctreeMetadata meta;
  std::map<lod::NodeKey, std::vector<PointRecord>> nodes; // every node with points in its subtree
  std::set<lod::NodeKey> damagedPoints;                   // readNode throws InputError
  std::set<lod::NodeKey> damagedChildren;                 // children throws InputError
  std::atomic<uint64_t> pointReads{0}, childReads{0};

  const lod::OctreeMetadata& metadata() const override { return meta; }
  lod::NodeInfo root() override { return info({}); }
  std::vector<lod::NodeInfo> children(const lod::NodeInfo& node) override {
    ++childReads;
    if (damagedChildren.count(node.key))
      throw InputError(meta.source + ": the hierarchy below node " + node.key.potreeName() + " is truncated");
    std::vector<lod::NodeInfo> kids;
    for (int i = 0; i < 8; ++i)
      if (nodes.count(node.key.child(i))) kids.push_back(info(node.key.child(i)));
    return kids;
  }
  std::vector<PointRecord> readNode(const lod::NodeInfo& node) override {
    ++pointReads;
    if (damagedPoints.count(node.key))
      throw InputError(meta.source + ": node " + node.key.potreeName() + " ends past the end of octree.bin");
    return nodes.at(node.key);
  }
  uint64_t nodeBytes(const lod::NodeInfo& node) override { return 24 * nodes.at(node.key).size(); }

  lod::NodeInfo info(const lod::NodeKey& key) const {
    lod::NodeInfo n;
    n.key = key;
    auto found = nodes.find(key);
    n.pointCount = found == nodes.end() ? 0 : found->second.size();
    for (int i = 0; i < 8; ++i)
      if (nodes.count(key.child(i))) n.childMask |= uint8_t(1u << i);
    return n;
  }
  uint64_t points() const {
    uint64_t n = 0;
    for (const auto& [key, records] : nodes)
      n += records.size();
    return n;
  }
  // Every point, node after node in key order (the order the LOD methods number them in).
  PointCloud cloud() const {
    PointCloud c;
    c.scale = meta.scale;
    c.offset = meta.offset;
    for (const auto& [key, records] : nodes)
      appendRecords(c, records.data(), records.size(), meta.fields, meta.fields.colorMax > 255 ? 8 : 0);
    computeBounds(c);
    return c;
  }
  // Colors that name points by their place in cloud()'s order (1, 2, 3...): both the brute-force methods
  // (the smaller color) and the LOD methods (the smaller index) then break depth ties alike.
  void colorsAreIndices() {
    uint32_t i = 0;
    for (auto& [key, records] : nodes)
      for (PointRecord& r : records) {
        ++i;
        r.rgb[0] = uint16_t(i & 0xFF);
        r.rgb[1] = uint16_t((i >> 8) & 0xFF);
        r.rgb[2] = uint16_t((i >> 16) & 0xFF);
      }
  }
};

// The rule of the header, on a cube around the cloud's bounds. The cloud's colors become 8-bit RGB.
inline void buildOctree(MemoryOctree& tree, const PointCloud& cloud, size_t leafLimit = 2000,
                        double cellsPerEdge = 32) {
  tree.meta.source = "memory octree";
  tree.meta.format = "test";
  tree.meta.scale = cloud.scale;
  tree.meta.offset = cloud.offset;
  tree.meta.bounds = cloud.bounds;
  const glm::dvec3 size = cloud.bounds.size();
  const double edge = std::max({size.x, size.y, size.z, 1e-6}) * 1.001;
  tree.meta.cube.min = cloud.bounds.min - 0.0005 * edge;
  tree.meta.cube.max = tree.meta.cube.min + glm::dvec3(edge);
  tree.meta.spacing = edge / cellsPerEdge;
  tree.meta.pointCount = cloud.size();
  tree.meta.fields.color = cloud.hasColor();
  tree.meta.fields.colorMax = 255;
  std::vector<PointRecord> records(cloud.size());
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    PointRecord& r = records[i];
    r.x = cloud.positions[3 * i];
    r.y = cloud.positions[3 * i + 1];
    r.z = cloud.positions[3 * i + 2];
    if (cloud.hasColor())
      for (int c = 0; c < 3; ++c)
        r.rgb[c] = uint16_t((cloud.colors[i] >> (8 * c)) & 0xFF);
  }
  struct Work {
    lod::NodeKey key;
    std::vector<uint32_t> points;
  };
  std::vector<Work> stack(1);
  for (uint32_t i = 0; i < records.size(); ++i)
    stack[0].points.push_back(i);
  while (!stack.empty()) {
    Work work = std::move(stack.back());
    stack.pop_back();
    std::vector<PointRecord>& kept = tree.nodes[work.key];
    if (work.points.size() <= leafLimit || work.key.level >= 20) {
      for (uint32_t i : work.points)
        kept.push_back(records[i]);
      continue;
    }
    const Bounds cube = tree.meta.nodeCube(work.key);
    const double cell = (cube.max.x - cube.min.x) / cellsPerEdge;
    std::set<std::tuple<int64_t, int64_t, int64_t>> taken;
    std::vector<uint32_t> children[8];
    for (uint32_t i : work.points) {
      const glm::dvec3 p = cloud.world(i);
      const glm::dvec3 c = glm::floor((p - cube.min) / cell);
      if (taken.insert({int64_t(c.x), int64_t(c.y), int64_t(c.z)}).second) {
        kept.push_back(records[i]);
        continue;
      }
      const glm::dvec3 mid = cube.center();
      children[(p.x >= mid.x ? 4 : 0) | (p.y >= mid.y ? 2 : 0) | (p.z >= mid.z ? 1 : 0)].push_back(i);
    }
    for (int k = 7; k >= 0; --k)
      if (!children[k].empty()) stack.push_back({work.key.child(k), std::move(children[k])});
  }
}

} // namespace pointrast::test
