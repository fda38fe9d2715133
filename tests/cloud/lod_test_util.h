// Octree checks shared by the builder's tests: a NodeSink that keeps nodes in memory, and the properties
// every built octree must have, checked against the input points.
#pragma once

#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cloud/generate.h"
#include "cloud/lod_assemble.h"
#include "cloud/lod_build.h"
#include "cloud/lod_grid.h"

namespace pointrast::lodtest {

using lod::NodeKey;

struct WrittenNode {
  NodeKey key;
  std::vector<PointRecord> records;
};

class MemorySink : public lod::NodeSink {
public:
  void writeNode(const NodeKey& key, const PointRecord* records, const uint8_t*, size_t count) override {
    nodes.push_back({key, std::vector<PointRecord>(records, records + count)});
    // FNV-1a over the key and the records, in write order: what an octree file's bytes depend on.
    mix(&key, sizeof key);
    uint64_t n = count;
    mix(&n, sizeof n);
    mix(records, count * sizeof(PointRecord));
  }
  std::vector<WrittenNode> nodes;
  uint64_t hash = 0xcbf29ce484222325ull;

private:
  void mix(const void* data, size_t size) {
    const auto* p = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < size; ++i)
      hash = (hash ^ p[i]) * 0x100000001b3ull;
  }
};

inline bool recordLess(const PointRecord& a, const PointRecord& b) {
  return std::memcmp(&a, &b, sizeof a) < 0;
}

inline PointRecord withoutColor(PointRecord r) {
  r.rgb[0] = r.rgb[1] = r.rgb[2] = 0;
  return r;
}

// Records of a PointCloud, colors as 8-bit values, point source id = index % 7 (so it is not all zero).
inline std::vector<PointRecord> recordsOf(const PointCloud& cloud) {
  std::vector<PointRecord> out(cloud.size());
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    PointRecord& r = out[i];
    r.x = cloud.positions[3 * i];
    r.y = cloud.positions[3 * i + 1];
    r.z = cloud.positions[3 * i + 2];
    if (cloud.hasColor()) {
      r.rgb[0] = cloud.colors[i] & 0xFF;
      r.rgb[1] = (cloud.colors[i] >> 8) & 0xFF;
      r.rgb[2] = (cloud.colors[i] >> 16) & 0xFF;
    }
    if (!cloud.intensity.empty()) r.intensity = cloud.intensity[i];
    if (!cloud.classification.empty()) r.classification = cloud.classification[i];
    if (!cloud.returnNumber.empty()) r.returnNumber = cloud.returnNumber[i];
    r.pointSourceId = static_cast<uint16_t>(i % 7);
  }
  return out;
}

// Records of generated terrain (`n` points).
inline std::vector<PointRecord> terrainRecords(uint64_t n, uint64_t seed = 3) {
  GenerateOptions options;
  options.points = n;
  options.seed = seed;
  options.progress = false;
  return recordsOf(generateScene(Scene::Terrain, options));
}

// A side x side x 3 lattice, 10 units apart with up to 4 units of jitter, random colors, intensities, and
// classes, returns and sources by row: on a coarse grid (4 cells per node edge) cells hold many points.
inline std::vector<PointRecord> latticeRecords(int side) {
  std::vector<PointRecord> records;
  std::mt19937_64 rng(5);
  for (int x = 0; x < side; ++x)
    for (int y = 0; y < side; ++y)
      for (int z = 0; z < 3; ++z) {
        PointRecord r;
        r.x = x * 10 + int(rng() % 5);
        r.y = y * 10 + int(rng() % 5);
        r.z = z * 7;
        r.rgb[0] = uint16_t(rng() % 65536);
        r.rgb[1] = uint16_t(rng() % 256);
        r.rgb[2] = uint16_t(x * 6);
        r.intensity = uint16_t(rng());
        r.classification = uint8_t(x % 3);
        r.returnNumber = 1;
        r.pointSourceId = uint16_t(y);
        records.push_back(r);
      }
  return records;
}

// Cuts records into pieces of `size` (the shape readers deliver).
inline lod::Pieces piecesOf(const std::vector<PointRecord>& records, size_t size) {
  lod::Pieces pieces;
  for (size_t b = 0; b < records.size(); b += size)
    pieces.emplace_back(records.begin() + ptrdiff_t(b),
                        records.begin() + ptrdiff_t(std::min(records.size(), b + size)));
  return pieces;
}

inline lod::LodGrid gridOf(const std::vector<PointRecord>& records, glm::dvec3 scale = glm::dvec3(0.001),
                           glm::dvec3 offset = glm::dvec3(0), int gridLevels = lod::kDefaultGridLevels) {
  lod::LodRunOptions quiet;
  quiet.progress = false;
  return lod::makeLodGrid(lod::quantBoxOf(piecesOf(records, 1 << 20), quiet), scale, offset, gridLevels);
}

struct Built {
  MemorySink sink;
  lod::LodBuildStats stats;
};

inline Built build(const std::vector<PointRecord>& records, const lod::LodGrid& grid,
                   const lod::LodParams& params, unsigned threads = 2, uint64_t chunkPoints = 0,
                   size_t pieceSize = 100'000) {
  Built b;
  lod::LodRunOptions options;
  options.threads = threads;
  options.progress = false;
  options.chunkPoints = chunkPoints;
  b.stats = lod::buildInMemory(piecesOf(records, pieceSize), grid, params, b.sink, options);
  return b;
}

// Every property the builder promises (lod_index.h), checked against the input.
inline void expectValidOctree(const std::vector<WrittenNode>& nodes, const std::vector<PointRecord>& input,
                              const lod::LodGrid& grid, const lod::LodParams& params) {
  ASSERT_FALSE(nodes.empty());
  std::map<NodeKey, size_t> byKey;
  for (size_t i = 0; i < nodes.size(); ++i) {
    ASSERT_TRUE(byKey.emplace(nodes[i].key, i).second) << "node " << nodes[i].key.potreeName() << " twice";
    ASSERT_FALSE(nodes[i].records.empty());
    ASSERT_LE(nodes[i].key.level, lod::kMaxLevel);
  }
  ASSERT_TRUE(byKey.count(NodeKey{}));

  // Written in post-order: children in index order, then the parent; so the root is last.
  auto postOrderLess = [](const NodeKey& a, const NodeKey& b) {
    const int level = std::min(a.level, b.level);
    const NodeKey ra{level, a.x >> (a.level - level), a.y >> (a.level - level), a.z >> (a.level - level)};
    const NodeKey rb{level, b.x >> (b.level - level), b.y >> (b.level - level), b.z >> (b.level - level)};
    if (ra == rb) return a.level > b.level; // the deeper one is inside the other: it comes first
    return lod::cellOfKey(ra) < lod::cellOfKey(rb);
  };
  for (size_t i = 1; i < nodes.size(); ++i)
    ASSERT_TRUE(postOrderLess(nodes[i - 1].key, nodes[i].key))
        << nodes[i - 1].key.potreeName() << " before " << nodes[i].key.potreeName();

  // Input points per cube: a node's cube count decides leaf or inner.
  std::vector<uint64_t> codes(input.size());
  for (size_t i = 0; i < input.size(); ++i)
    codes[i] = grid.code(input[i]);
  std::sort(codes.begin(), codes.end());
  auto cubeCount = [&](const NodeKey& key) {
    const int shift = 3 * (lod::kCodeLevels - key.level);
    const uint64_t cell = lod::cellOfKey(key);
    auto lo = std::lower_bound(codes.begin(), codes.end(), cell << shift);
    auto hi =
        key.level == 0 ? codes.end() : std::lower_bound(codes.begin(), codes.end(), (cell + 1) << shift);
    return uint64_t(hi - lo);
  };

  const double tolerance = std::max({grid.scale.x, grid.scale.y, grid.scale.z}); // one quantum
  lod::OctreeMetadata meta;
  meta.cube = grid.cube;
  std::vector<PointRecord> all, allNoColor;
  for (const WrittenNode& node : nodes) {
    const NodeKey& key = node.key;
    if (key.level > 0) {
      ASSERT_TRUE(byKey.count(key.parent())) << key.potreeName() << " has no parent";
    }
    const bool inner = cubeCount(key) > params.leafPoints && key.level < lod::kMaxLevel;
    bool hasChildren = false;
    for (int c = 0; c < 8; ++c)
      hasChildren = hasChildren || byKey.count(key.child(c));
    if (hasChildren) {
      ASSERT_TRUE(inner) << key.potreeName() << " has children but holds few points";
    }
    const Bounds cube = meta.nodeCube(key);
    std::vector<uint64_t> cells;
    for (const PointRecord& r : node.records) {
      ASSERT_EQ(lod::keyOfCode(grid.code(r), key.level), key) << key.potreeName();
      const glm::dvec3 w = glm::dvec3(r.x, r.y, r.z) * grid.scale + grid.offset;
      for (int a = 0; a < 3; ++a) {
        ASSERT_GE(w[a], cube.min[a] - tolerance) << key.potreeName();
        ASSERT_LE(w[a], cube.max[a] + tolerance) << key.potreeName();
      }
      cells.push_back(grid.code(r) >> 3 * (lod::kCodeLevels - grid.sampleLevel(key.level)));
      all.push_back(r);
      allNoColor.push_back(withoutColor(r));
    }
    if (inner) {
      // One point per cell of the node's sample grid: spacing halves with every level.
      std::sort(cells.begin(), cells.end());
      ASSERT_TRUE(std::adjacent_find(cells.begin(), cells.end()) == cells.end()) << key.potreeName();
    } else if (key.level < lod::kMaxLevel) {
      ASSERT_LE(node.records.size(), params.leafPoints) << key.potreeName();
    }
  }
  // Every input point is in exactly one node, with its exact integers and attributes.
  ASSERT_EQ(all.size(), input.size());
  std::vector<PointRecord> expected = input;
  if (params.averageColors) {
    for (PointRecord& r : expected)
      r = withoutColor(r);
    all = allNoColor;
  }
  std::sort(all.begin(), all.end(), recordLess);
  std::sort(expected.begin(), expected.end(), recordLess);
  for (size_t i = 0; i < all.size(); ++i)
    ASSERT_EQ(std::memcmp(&all[i], &expected[i], sizeof(PointRecord)), 0) << "record " << i;
}

inline bool isInside(const NodeKey& inner, const NodeKey& outer) {
  if (inner.level < outer.level) return false;
  const int up = inner.level - outer.level;
  return (inner.x >> up) == outer.x && (inner.y >> up) == outer.y && (inner.z >> up) == outer.z;
}

// Color filtering and the choice of the point that stays (lod_index.h), on a cloud whose positions are
// unique: every point of an inner node is the one closest to its sample cell's center among the points
// of that cell that reached the node (the node's and its descendants'), and its color is their average
// input color, rounded to nearest.
inline void expectFilteredColors(const std::vector<WrittenNode>& nodes, const std::vector<PointRecord>& input,
                                 const lod::LodGrid& grid, const lod::LodParams& params) {
  std::map<std::array<int32_t, 3>, PointRecord> original;
  for (const PointRecord& r : input)
    ASSERT_TRUE(original.emplace(std::array<int32_t, 3>{r.x, r.y, r.z}, r).second)
        << "positions must be unique";
  std::map<NodeKey, const WrittenNode*> byKey;
  for (const WrittenNode& n : nodes)
    byKey[n.key] = &n;
  uint64_t averagedOverMany = 0;
  for (const WrittenNode& node : nodes) {
    bool hasChildren = false;
    for (int c = 0; c < 8; ++c)
      hasChildren = hasChildren || byKey.count(node.key.child(c));
    if (!hasChildren) continue; // a leaf, or an inner node: checked only where it is certainly inner
    const int cellLevel = grid.sampleLevel(node.key.level);
    const int shift = 3 * (lod::kCodeLevels - cellLevel);
    std::map<uint64_t, std::vector<PointRecord>> reached; // sample cell -> points that reached the node
    for (const WrittenNode& other : nodes)
      if (isInside(other.key, node.key))
        for (const PointRecord& r : other.records)
          reached[grid.code(r) >> shift].push_back(original.at({r.x, r.y, r.z}));
    for (const PointRecord& p : node.records) {
      const uint64_t cell = grid.code(p) >> shift;
      const std::vector<PointRecord>& points = reached.at(cell);
      uint64_t sum[3] = {0, 0, 0};
      for (const PointRecord& q : points)
        for (int c = 0; c < 3; ++c)
          sum[c] += q.rgb[c];
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(p.rgb[c], params.averageColors ? (sum[c] + points.size() / 2) / points.size()
                                                 : original.at({p.x, p.y, p.z}).rgb[c])
            << node.key.potreeName() << " channel " << c;
      averagedOverMany += points.size() > 1;
      // Nearest the cell's center, as the grid measures it (doubled quanta, integers for equal scales).
      const lod::LodGrid::Center center = grid.cellCenter(cell, cellLevel);
      for (const PointRecord& q : points) {
        if (grid.isotropic)
          ASSERT_LE(grid.centerDistanceIsotropic(center, p), grid.centerDistanceIsotropic(center, q))
              << node.key.potreeName();
        else
          ASSERT_LE(grid.centerDistance(center, p), grid.centerDistance(center, q)) << node.key.potreeName();
      }
    }
  }
  EXPECT_GT(averagedOverMany, 0u) << "the cloud never puts two points in one cell: the test proves nothing";
}

} // namespace pointrast::lodtest
