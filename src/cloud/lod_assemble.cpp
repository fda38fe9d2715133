#include "cloud/lod_assemble.h"

#include <algorithm>
#include <cassert>

namespace pointrast::lod {

std::unique_ptr<PreparedNode> NodeSink::prepare(const NodeKey&, const PointRecord*, const uint8_t*,
                                                size_t) const {
  return nullptr;
}

void NodeSink::writePrepared(const NodeKey& key, PreparedNode*, const PointRecord* records,
                             const uint8_t* tails, size_t count) {
  writeNode(key, records, tails, count);
}

void NodeSink::finishPrepared(std::unique_ptr<PreparedNode>) const {}

const uint8_t* OctreeAssembler::tailsOf(const std::vector<uint8_t>& tails, uint64_t first) const {
  return tailBytes_ ? tails.data() + first * tailBytes_ : nullptr;
}

void OctreeAssembler::prepare(ChunkNodes& chunk) const {
  chunk.prepared.clear();
  chunk.prepared.reserve(chunk.nodes.size());
  for (const ChunkNodes::Node& node : chunk.nodes)
    chunk.prepared.push_back(sink_.prepare(node.key, chunk.records.data() + node.first,
                                           tailsOf(chunk.tails, node.first),
                                           static_cast<size_t>(node.count)));
}

void OctreeAssembler::write(const NodeKey& key, const PointRecord* records, const uint8_t* tails,
                            size_t count) {
  if (count == 0) return; // an ancestor whose points all went to its own ancestors does not exist
  sink_.writeNode(key, records, tails, count);
  counted(key, count);
}

void OctreeAssembler::counted(const NodeKey& key, uint64_t count) {
  stats_.points += count;
  ++stats_.nodes;
  stats_.levels = std::max(stats_.levels, key.level + 1);
}

void OctreeAssembler::closeDeeperThan(int level) {
  while (static_cast<int>(open_.size()) > level + 1) {
    Open& last = open_.back();
    write(last.key, last.records.data(), tailBytes_ ? last.tails.data() : nullptr, last.records.size());
    open_.pop_back();
  }
}

void OctreeAssembler::add(ChunkNodes& chunk) {
  const NodeKey& key = chunk.chunk;
  // Ancestors of earlier chunks that are not ancestors of this one are complete: write them, deepest
  // first (post-order).
  int keep = 0;
  while (keep < static_cast<int>(open_.size()) && keep < key.level) {
    const int up = key.level - keep;
    const NodeKey ancestor{keep, key.x >> up, key.y >> up, key.z >> up};
    if (!(open_[static_cast<size_t>(keep)].key == ancestor)) break;
    ++keep;
  }
  closeDeeperThan(keep - 1);
  // Open this chunk's ancestors from the first one not open yet, and give each its subsample share.
  for (int level = keep; level < key.level; ++level) {
    const int up = key.level - level;
    open_.push_back({NodeKey{level, key.x >> up, key.y >> up, key.z >> up}, {}, {}});
  }
  assert(chunk.topCounts.size() == static_cast<size_t>(key.level));
  size_t offset = 0;
  for (int level = 0; level < key.level; ++level) {
    const size_t n = static_cast<size_t>(chunk.topCounts[static_cast<size_t>(level)]);
    std::vector<PointRecord>& dst = open_[static_cast<size_t>(level)].records;
    dst.insert(dst.end(), chunk.top.begin() + ptrdiff_t(offset), chunk.top.begin() + ptrdiff_t(offset + n));
    if (tailBytes_) {
      std::vector<uint8_t>& t = open_[static_cast<size_t>(level)].tails;
      t.insert(t.end(), chunk.topTails.begin() + ptrdiff_t(offset * tailBytes_),
               chunk.topTails.begin() + ptrdiff_t((offset + n) * tailBytes_));
    }
    offset += n;
  }
  for (size_t i = 0; i < chunk.nodes.size(); ++i) {
    const ChunkNodes::Node& node = chunk.nodes[i];
    const PointRecord* records = chunk.records.data() + node.first;
    sink_.writePrepared(node.key, i < chunk.prepared.size() ? chunk.prepared[i].get() : nullptr, records,
                        tailsOf(chunk.tails, node.first), static_cast<size_t>(node.count));
    counted(node.key, node.count);
  }
}

void OctreeAssembler::finishChunk(ChunkNodes& chunk) const {
  for (std::unique_ptr<PreparedNode>& prepared : chunk.prepared)
    if (prepared) sink_.finishPrepared(std::move(prepared));
  chunk.prepared.clear();
}

void OctreeAssembler::finish() {
  closeDeeperThan(-1);
}

} // namespace pointrast::lod
