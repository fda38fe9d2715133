// Assembling an octree from its chunks: the nodes that span chunks (the chunks' ancestors) gather their
// subsamples from every chunk below them, and every node goes to a NodeSink exactly once, in one
// canonical order whatever the chunks and threads: depth-first post-order (children in index order,
// then the parent). Post-order is what streaming allows: a chunk's subtree is written as soon as the
// chunks before it are, and an ancestor right after its last chunk, so only the ancestors on the current
// path are held in memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "cloud/lod_index.h"

namespace pointrast::lod {

// Where built nodes go: an octree writer (io::PotreeWriter through an adapter), or memory in tests.
class NodeSink {
public:
  virtual ~NodeSink() = default;
  // One node's points; every node once, in the order the builder decides. Called from one thread at a
  // time (not always the same one). tails: the records' tails one after another (LodParams::tailBytes
  // each), null where points carry none.
  virtual void writeNode(const NodeKey& key, const PointRecord* records, const uint8_t* tails,
                         size_t count) = 0;

  // Optional split of writeNode for sinks with work that needs no order (encoding a node, writing its
  // bytes once their place is known): prepare() runs on any thread, several at once, as soon as a node's
  // points are final; writePrepared() then takes its result in the builder's order instead of
  // writeNode() (where only the order matters: the node's place in the output); finishPrepared() last
  // does the rest on any thread, several at once (writing the bytes there). Every node given to
  // writePrepared() reaches finishPrepared() before the build returns. Nodes that span chunks go
  // through writeNode().
  // The default prepares nothing, writes through writeNode() and has nothing to finish.
  virtual std::unique_ptr<PreparedNode> prepare(const NodeKey& key, const PointRecord* records,
                                                const uint8_t* tails, size_t count) const;
  virtual void writePrepared(const NodeKey& key, PreparedNode* prepared, const PointRecord* records,
                             const uint8_t* tails, size_t count);
  virtual void finishPrepared(std::unique_ptr<PreparedNode> prepared) const;
};

struct AssembleStats {
  uint64_t points = 0;
  uint64_t nodes = 0;
  int levels = 0; // deepest node's level + 1
};

class OctreeAssembler {
public:
  // tailBytes: LodParams::tailBytes of the chunks.
  explicit OctreeAssembler(NodeSink& sink, uint32_t tailBytes = 0) : sink_(sink), tailBytes_(tailBytes) {}

  // The sink's prepare() for the chunk's own nodes, on the calling thread (any, several at once).
  void prepare(ChunkNodes& chunk) const;
  // Chunks in Morton order (planChunks' order), each once.
  void add(ChunkNodes& chunk);
  // The sink's finishPrepared() for a chunk after its add(), on the calling thread (any, several at once).
  void finishChunk(ChunkNodes& chunk) const;
  // Writes the ancestors still open. Call once, after the last chunk.
  void finish();
  const AssembleStats& stats() const { return stats_; }

private:
  void write(const NodeKey& key, const PointRecord* records, const uint8_t* tails, size_t count);
  void counted(const NodeKey& key, uint64_t count);
  const uint8_t* tailsOf(const std::vector<uint8_t>& tails, uint64_t first) const;
  void closeDeeperThan(int level);

  struct Open {
    NodeKey key;
    std::vector<PointRecord> records;
    std::vector<uint8_t> tails;
  };
  NodeSink& sink_;
  uint32_t tailBytes_ = 0;
  std::vector<Open> open_; // open_[L]: the open ancestor at level L (the current chunk's path)
  AssembleStats stats_;
};

} // namespace pointrast::lod
