#include "cloud/octree.h"

namespace pointrast::lod {

void forEachNode(NodeSource& source, const std::function<bool(const NodeInfo&)>& visit) {
  // An explicit stack: a hostile hierarchy may be deep, and recursion would follow it onto the C stack.
  std::vector<NodeInfo> stack{source.root()};
  while (!stack.empty()) {
    NodeInfo node = stack.back();
    stack.pop_back();
    if (!visit(node) || node.childMask == 0) continue;
    std::vector<NodeInfo> kids = source.children(node);
    for (auto it = kids.rbegin(); it != kids.rend(); ++it)
      stack.push_back(*it);
  }
}

} // namespace pointrast::lod
