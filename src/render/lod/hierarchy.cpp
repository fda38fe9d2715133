#include "render/lod/hierarchy.h"

#include <cassert>

#include "base/error.h"

namespace pointrast::lod {

Hierarchy::Hierarchy(const OctreeMetadata& metadata, const NodeInfo& root) : metadata_(metadata) {
  if (root.key != NodeKey{})
    throw InputError(metadata.source + ": the octree's root is not the node at level 0 (" +
                     root.key.potreeName() + ")");
  if (root.pointCount > kMaxNodePoints)
    throw InputError(metadata.source + ": the octree's root claims " + std::to_string(root.pointCount) +
                     " points, more than a node can hold");
  HostNode node;
  node.info = root;
  node.childrenKnown = root.childMask == 0;
  nodes_.push_back(node);
}

std::string Hierarchy::describe(uint32_t id) const {
  return "node " + nodes_[id].info.key.potreeName() + " of " + metadata_.source;
}

void Hierarchy::setChildren(uint32_t id, const std::vector<NodeInfo>& children) {
  assert(id < nodes_.size());
  if (nodes_[id].childrenKnown) return;
  const NodeInfo parent = nodes_[id].info;
  auto fail = [&](const std::string& why) { throw InputError(metadata_.source + ": " + why); };
  if (parent.key.level >= kMaxLevel && !children.empty())
    fail("the hierarchy is deeper than " + std::to_string(kMaxLevel) + " levels below " +
         parent.key.potreeName());
  int previous = -1;
  for (const NodeInfo& child : children) {
    const int index = child.key.childIndex();
    const std::string name = child.key.potreeName();
    if (child.key != parent.key.child(index))
      fail("node " + name + " is listed as a child of " + parent.key.potreeName() +
           " but is not one of its eight");
    if (!(parent.childMask >> index & 1))
      fail("node " + name + " is listed as a child of " + parent.key.potreeName() +
           ", whose child mask does not have it");
    if (index <= previous)
      fail("the children of " + parent.key.potreeName() + " are listed twice or out of order");
    if (child.pointCount > kMaxNodePoints)
      fail("node " + name + " claims " + std::to_string(child.pointCount) +
           " points, more than a node can hold");
    previous = index;
  }
  const uint32_t first = uint32_t(nodes_.size());
  for (const NodeInfo& child : children) {
    HostNode node;
    node.info = child;
    node.parent = id;
    node.childrenKnown = child.childMask == 0;
    nodes_.push_back(node);
  }
  HostNode& n = nodes_[id];
  n.firstChild = children.empty() ? kNoNode : first;
  n.childCount = uint8_t(children.size());
  n.childrenKnown = true;
}

} // namespace pointrast::lod
