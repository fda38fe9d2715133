// Level-of-detail octrees: the node model that every LOD source serves (pointrast's own octrees and
// PotreeConverter's in the Potree 2.0 layout, COPC, EPT) and every consumer reads (the LOD renderer and
// its GPU node cache, `info`, `convert`). No files, no Vulkan: sources live in src/io, consumers in
// src/render and app/.
//
// An octree is additive ("layered point cloud", Potree 2.0; COPC and EPT alike): every point is stored in
// exactly one node; an inner node holds a subsample of its subtree whose spacing halves per level, so a
// node and all its ancestors together are a coarse version of the node's region.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cloud/cloud.h"
#include "cloud/point_record.h"

namespace pointrast::lod {

// A node by its place in the tree: level (root 0) and integer cell coordinates at that level,
// 0 <= x, y, z < 2^level, as COPC's and EPT's voxel keys (D-X-Y-Z). A child's index within its parent is
// (dx << 2) | (dy << 1) | dz with d the low bit of the child's coordinate, as the digits of Potree node
// names ("r", "r0", "r07"...).
struct NodeKey {
  int32_t level = 0;
  int32_t x = 0, y = 0, z = 0;

  NodeKey child(int index) const {
    return {level + 1, 2 * x + ((index >> 2) & 1), 2 * y + ((index >> 1) & 1), 2 * z + (index & 1)};
  }
  NodeKey parent() const { return {level - 1, x >> 1, y >> 1, z >> 1}; }
  int childIndex() const { return ((x & 1) << 2) | ((y & 1) << 1) | (z & 1); }
  friend bool operator==(const NodeKey&, const NodeKey&) = default;
  friend auto operator<=>(const NodeKey&, const NodeKey&) = default;

  // "r" followed by one child-index digit per level ("r", "r0", "r07").
  std::string potreeName() const {
    std::string name(static_cast<size_t>(level) + 1, 'r');
    for (int32_t l = level; l > 0; --l)
      name[static_cast<size_t>(l)] = char('0' + (((x >> (level - l)) & 1) << 2 | ((y >> (level - l)) & 1) << 1 |
                                              ((z >> (level - l)) & 1)));
    return name;
  }
};

struct NodeKeyHash {
  size_t operator()(const NodeKey& k) const {
    uint64_t h = uint64_t(uint32_t(k.level)) * 0x9E3779B97F4A7C15ull;
    h ^= (uint64_t(uint32_t(k.x)) + 0x7F4A7C15ull + (h << 6) + (h >> 2)) * 0xBF58476D1CE4E5B9ull;
    h ^= (uint64_t(uint32_t(k.y)) + 0x94D049BBull + (h << 6) + (h >> 2)) * 0x94D049BB133111EBull;
    h ^= uint64_t(uint32_t(k.z)) + (h << 6) + (h >> 2);
    return size_t(h);
  }
};

// What a source says about the whole octree.
struct OctreeMetadata {
  std::string source;      // file or folder name, for messages
  std::string format;      // "Potree 2.0 (DEFAULT)", "Potree 2.0 (BROTLI)", "COPC 1.0", "EPT 1.0 (laszip)"...
  Bounds cube;             // the root's cube (all edges equal), world coordinates
  Bounds bounds;           // tight bounds of the points (the source's claim)
  double spacing = 0;      // point spacing of the root's subsample; level L has spacing / 2^L
  glm::dvec3 scale{0.001}; // records' positions: world = q * scale + offset
  glm::dvec3 offset{0.0};
  uint64_t pointCount = 0; // as the source states it
  RecordFields fields;     // which record fields carry data
  int depth = -1;          // levels below the root when the source states it (-1: unknown until read)

  // The cube of a node: the root's cube halved `level` times.
  Bounds nodeCube(const NodeKey& key) const {
    const double edge = (cube.max.x - cube.min.x) / double(uint64_t(1) << key.level);
    Bounds b;
    b.min = cube.min + glm::dvec3(key.x, key.y, key.z) * edge;
    b.max = b.min + glm::dvec3(edge);
    return b;
  }
  double nodeSpacing(const NodeKey& key) const { return spacing / double(uint64_t(1) << key.level); }
};

// One node as the hierarchy describes it.
struct NodeInfo {
  NodeKey key;
  uint64_t pointCount = 0; // points stored in this node (not its subtree)
  uint8_t childMask = 0;   // bit i: child i exists (child(i) has points in its subtree)
};

// Serves an octree's hierarchy on demand and each node's points on their own. Implementations read
// files (src/io): a Potree 2.0 folder, a COPC file, an EPT dataset. Every member may be called from
// several threads at once (the renderer's streaming workers read nodes in parallel). Damaged data throws
// InputError with one sentence naming the file; a source never hangs or allocates beyond what its files
// can hold, whatever a hierarchy claims.
class NodeSource {
public:
  virtual ~NodeSource() = default;
  virtual const OctreeMetadata& metadata() const = 0;
  virtual NodeInfo root() = 0;
  // The existing children of a node, in child-index order, reading hierarchy data as needed (a Potree
  // hierarchy chunk behind a proxy node, a COPC hierarchy page, an EPT hierarchy file) and keeping it.
  virtual std::vector<NodeInfo> children(const NodeInfo& node) = 0;
  // The points of one node, decoded on their own; exactly node.pointCount records.
  virtual std::vector<PointRecord> readNode(const NodeInfo& node) = 0;
  // Bytes a node occupies in its file (what reading it costs), for streaming statistics.
  virtual uint64_t nodeBytes(const NodeInfo& node) = 0;
};

// Visits every node of a source depth-first (parents before children, children in index order), reading
// the whole hierarchy. Returning false from visit skips the node's subtree.
void forEachNode(NodeSource& source, const std::function<bool(const NodeInfo&)>& visit);

} // namespace pointrast::lod
