// Potree 2.0 hierarchy.bin: 22-byte node records in chunks of `stepSize` levels linked by proxy records
// (layout in io/potree/potree_format.h), written from a list of nodes and parsed one chunk at a time.
#include <cassert>
#include <deque>
#include <stdexcept>
#include <unordered_map>

#include "io/io_util.h"
#include "io/potree/potree_format.h"

namespace pointrast::io::potree {

using namespace detail;

void storeRecord(uint8_t* dst, const Record& record) {
  dst[0] = record.type;
  dst[1] = record.childMask;
  storeLE<uint32_t>(dst + 2, record.pointCount);
  storeLE<int64_t>(dst + 6, record.byteOffset);
  storeLE<int64_t>(dst + 14, record.byteSize);
}

Record loadRecord(const uint8_t* src) {
  Record r;
  r.type = src[0];
  r.childMask = src[1];
  r.pointCount = loadLE<uint32_t>(src + 2);
  r.byteOffset = loadLE<int64_t>(src + 6);
  r.byteSize = loadLE<int64_t>(src + 14);
  return r;
}

namespace {

struct Chunk {
  size_t root = 0;             // node index
  std::vector<size_t> members; // breadth-first, the root first
  uint64_t offset = 0;
};

// Child masks from the keys; every node but the root must have its parent in the list.
std::vector<uint8_t> childMasks(const std::vector<WrittenNode>& nodes,
                                const std::unordered_map<lod::NodeKey, size_t, lod::NodeKeyHash>& index) {
  std::vector<uint8_t> masks(nodes.size(), 0);
  for (const WrittenNode& node : nodes) {
    if (node.key.level == 0) continue;
    auto parent = index.find(node.key.parent());
    assert(parent != index.end() && "every written node's parent is written too");
    if (parent == index.end())
      throw std::logic_error("Potree writer: node " + node.key.potreeName() +
                             " was written without its parent");
    masks[parent->second] |= uint8_t(1u << node.key.childIndex());
  }
  return masks;
}

} // namespace

HierarchyBytes buildHierarchy(std::vector<WrittenNode> nodes, int stepSize) {
  assert(stepSize >= 1);
  std::unordered_map<lod::NodeKey, size_t, lod::NodeKeyHash> index;
  index.reserve(nodes.size());
  for (size_t i = 0; i < nodes.size(); ++i) {
    [[maybe_unused]] bool inserted = index.emplace(nodes[i].key, i).second;
    assert(inserted && "each node is written once");
  }
  auto root = index.find(lod::NodeKey{});
  assert(root != index.end() && "the root is written");
  if (root == index.end()) throw std::logic_error("Potree writer: the root node was never written");
  const std::vector<uint8_t> masks = childMasks(nodes, index);

  HierarchyBytes out;
  auto isProxy = [&](size_t node, const Chunk& chunk) {
    return node != chunk.root && masks[node] != 0 &&
           nodes[node].key.level == nodes[chunk.root].key.level + stepSize;
  };
  // Chunks in breadth-first order of their roots: a queue of chunks, each gathered breadth-first.
  std::vector<Chunk> chunks{Chunk{root->second, {}, 0}};
  std::unordered_map<size_t, size_t> chunkOfProxy; // proxy node -> the chunk it stands for
  for (size_t c = 0; c < chunks.size(); ++c) {
    std::deque<size_t> queue{chunks[c].root};
    while (!queue.empty()) {
      const size_t node = queue.front();
      queue.pop_front();
      chunks[c].members.push_back(node);
      out.depth = std::max(out.depth, int(nodes[node].key.level));
      if (isProxy(node, chunks[c])) {
        chunkOfProxy[node] = chunks.size();
        chunks.push_back(Chunk{node, {}, 0});
        continue;
      }
      for (int child = 0; child < 8; ++child)
        if (masks[node] & (1u << child)) queue.push_back(index.at(nodes[node].key.child(child)));
    }
  }
  uint64_t offset = 0;
  for (Chunk& chunk : chunks) {
    chunk.offset = offset;
    offset += chunk.members.size() * kRecordBytes;
  }
  out.firstChunkSize = chunks[0].members.size() * kRecordBytes;

  out.bytes.resize(offset);
  uint8_t* dst = out.bytes.data();
  for (const Chunk& chunk : chunks) {
    for (size_t node : chunk.members) {
      const WrittenNode& n = nodes[node];
      Record r;
      r.childMask = masks[node];
      r.pointCount = n.pointCount;
      if (isProxy(node, chunk)) {
        const Chunk& target = chunks[chunkOfProxy.at(node)];
        r.type = kProxy;
        r.byteOffset = int64_t(target.offset);
        r.byteSize = int64_t(target.members.size() * kRecordBytes);
      } else {
        r.type = masks[node] ? kNormal : kLeaf;
        r.byteOffset = int64_t(n.byteOffset);
        r.byteSize = int64_t(n.byteSize);
      }
      storeRecord(dst, r);
      dst += kRecordBytes;
    }
  }
  return out;
}

std::vector<ChunkNode> parseChunk(const uint8_t* bytes, uint64_t size, const lod::NodeKey& root,
                                  const std::string& where) {
  if (size == 0 || size % kRecordBytes != 0)
    throw InputError(where +
                     strFormat(": the chunk of node %s (%llu bytes) is not a whole number of %llu-byte "
                               "records",
                               root.potreeName().c_str(), static_cast<unsigned long long>(size),
                               static_cast<unsigned long long>(kRecordBytes)));
  const uint64_t count = size / kRecordBytes;
  std::vector<lod::NodeKey> keys{root}; // the nodes the records describe, in record order
  std::vector<ChunkNode> out;
  out.reserve(static_cast<size_t>(count));
  for (uint64_t i = 0; i < count; ++i) {
    if (i >= keys.size())
      throw InputError(where + strFormat(": the chunk of node %s holds %llu records, but they describe only "
                                         "%zu nodes",
                                         root.potreeName().c_str(), static_cast<unsigned long long>(count),
                                         keys.size()));
    const lod::NodeKey key = keys[i];
    const Record r = loadRecord(bytes + i * kRecordBytes);
    if (r.type > kProxy)
      throw InputError(where + strFormat(": node %s has record type %u (0, 1 or 2 expected)",
                                         key.potreeName().c_str(), r.type));
    if (r.type == kProxy && i == 0)
      throw InputError(where + strFormat(": the chunk of node %s starts with a proxy record, a node standing "
                                         "for itself",
                                         key.potreeName().c_str()));
    if (r.type != kProxy && r.childMask != 0) {
      if (key.level >= kMaxLevel)
        throw InputError(where + strFormat(": node %s has children more than %d levels deep",
                                           key.potreeName().c_str(), kMaxLevel));
      for (int child = 0; child < 8; ++child) {
        if (!(r.childMask & (1u << child))) continue;
        if (keys.size() >= count)
          throw InputError(where +
                           strFormat(": the chunk of node %s describes more nodes than the %llu records "
                                     "it holds",
                                     root.potreeName().c_str(), static_cast<unsigned long long>(count)));
        keys.push_back(key.child(child));
      }
    }
    out.push_back({key, r});
  }
  return out;
}

} // namespace pointrast::io::potree
