// The part of an octree's hierarchy the host knows: nodes by id in the order they became known (the root is
// id 0), each with its parent and, once a reader listed them, its children under consecutive ids. It grows
// as the LOD renderer's selection reaches nodes whose children were not read yet (a Potree hierarchy chunk,
// a COPC page, an EPT file: NodeSource::children), and never shrinks: 48 bytes a node, 48 MB for a million
// nodes (a 20-billion-point octree of 20 k-point nodes).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cloud/octree.h"

namespace pointrast::lod {

constexpr uint32_t kNoNode = 0xFFFFFFFFu;

// Deepest level a hierarchy may reach: 2^30 cells per axis keep NodeKey's int32 coordinates exact, and a
// cube halved 30 times is a billionth of the root's edge, below any scale a source quantizes at.
constexpr int32_t kMaxLevel = 30;

// Most points one node may hold: the GPU counts a node's points in 32 bits and numbers the points of a
// frame in 32 bits; a node of more than 2^31 points (48 GiB of records) is a broken hierarchy, not data.
constexpr uint64_t kMaxNodePoints = uint64_t(1) << 31;

struct HostNode {
  NodeInfo info;
  uint32_t parent = kNoNode;
  uint32_t firstChild = kNoNode; // the children's ids are firstChild .. firstChild + childCount - 1
  uint8_t childCount = 0;
  bool childrenKnown = false; // true at once for a node without children (childMask 0)
};

class Hierarchy {
public:
  // Starts with the root. Throws InputError (naming metadata.source) for a root that is not at level 0 or
  // claims more than kMaxNodePoints points.
  Hierarchy(const OctreeMetadata& metadata, const NodeInfo& root);

  size_t size() const { return nodes_.size(); }
  const HostNode& node(uint32_t id) const { return nodes_[id]; }
  const OctreeMetadata& metadata() const { return metadata_; }

  // Records the children a source listed for node `id` (once; later calls are ignored). Throws InputError
  // naming the source and the node for a list that contradicts the node: a child that is not one of its
  // eight, one its child mask does not have, one listed twice or out of order, one past kMaxLevel or one
  // claiming more than kMaxNodePoints points.
  void setChildren(uint32_t id, const std::vector<NodeInfo>& children);

  // "node r0127 of cloud/metadata.json": for messages.
  std::string describe(uint32_t id) const;

private:
  OctreeMetadata metadata_;
  std::vector<HostNode> nodes_;
};

} // namespace pointrast::lod
