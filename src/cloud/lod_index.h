// Indexing one chunk: its points sorted into the canonical order, then its part of the octree built top
// down (PotreeConverter's "indexing" and "subsampling" phases). Pure: no files, no threads.
//
// The octree is a function of the points alone, so chunks and threads never change it:
//   - A node is inner when its cube holds more than leafPoints input points (and it is above kMaxLevel);
//     otherwise it is a leaf and keeps every point that reaches it. A node exists when at least one
//     point reaches it.
//   - The points that reach an inner node at level L are subsampled on the grid of its cube's cells at
//     level L + gridLevels (root spacing = edge / 2^gridLevels, halving per level): in each cell, the
//     point closest to the cell's center stays in the node; every other point goes on to the child whose
//     cube holds it.
//   - Color filtering: the point that stays takes the average color of the points of its cell that
//     reached the node (itself and all it stands for below), rounded to nearest; its position and other
//     attributes stay its own, exactly.
//   - Order: points sort by (Morton code, then the record's 24 bytes, then the item's ref: the point's
//     place in the input where points carry tails), a total order; a node's points are in that order, a
//     tie in distance goes to the first point in it.
//   - Tails (cloud/point_attributes.h): every point keeps its own; they travel beside the records.
// Every grid cell of a node lies within one chunk (chunks are never smaller than a root grid cell), so a
// chunk picks the points of its ancestors' subsamples by itself; only their nodes span chunks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "cloud/lod_grid.h"

namespace pointrast::lod {

struct LodParams {
  uint64_t leafPoints = 20'000; // a node whose cube holds more input points is split
  bool averageColors = true;    // color filtering; false keeps every point's own color
  uint32_t tailBytes = 0;       // bytes of each point's tail (0: no tails)
};

// A node's points as a sink prepared them for writing (an encoded node), see NodeSink::prepare().
struct PreparedNode {
  virtual ~PreparedNode() = default;
};

// One chunk's share of the octree.
struct ChunkNodes {
  NodeKey chunk;
  // Points the chunk gives to its ancestors' subsamples (levels 0 .. chunk.level - 1): topCounts[L]
  // records for level L, level after level, from the start of `top` (which may be longer). The ancestors
  // are inner nodes: chunks are planned so.
  std::vector<PointRecord> top;
  std::vector<uint8_t> topTails; // top's tails (LodParams::tailBytes each), where points carry them
  std::vector<uint64_t> topCounts;
  struct Node {
    NodeKey key;
    uint64_t first = 0, count = 0; // its points: records[first, first + count)
  };
  std::vector<Node> nodes; // the chunk's subtree (rooted at the chunk's cell), children before parents
  std::vector<PointRecord> records; // the nodes' points (where nodes say; it may be longer)
  std::vector<uint8_t> tails;       // records' tails, where points carry them
  // What the sink's prepare() made of each node (lod_assemble.h); empty until then.
  std::vector<std::unique_ptr<PreparedNode>> prepared;
};

// A point with its Morton code, as chunks hold them while they are indexed (40 B).
struct LodItem {
  uint64_t code; // LodGrid::code(record); bit 63 marks a point taken by a subsample while indexing
  PointRecord record;
  // Where points carry tails: the index of the point's tail in the chunk's tail store, in input order
  // (so it also decides the order of equal records); else 0.
  uint64_t ref;
};
static_assert(sizeof(LodItem) == 40);

// Buffers one thread reuses from chunk to chunk.
struct IndexScratch {
  std::vector<LodItem> items;   // a sort's scatter target
  std::vector<uint64_t> counts; // a sort's bucket positions
};

// Builds the part of the octree that the chunk's points make. items: every input point in the chunk's cube,
// grouped by count-level cell (grid.countLevel()), cells in Morton order, any order inside a cell;
// cellCounts: the points of each of those cells (the chunk's range of the histogram, empty cells
// included). The items are sorted in place and marked. chunk.level <= grid.countLevel(), and the chunk's
// ancestors must be inner nodes (their cubes hold more than params.leafPoints points), which planChunks
// guarantees when chunkLimit >= leafPoints. tails: the tail store the items' refs index (params.tailBytes
// bytes each), null when params.tailBytes is 0.
void indexChunk(ChunkNodes& out, IndexScratch& scratch, const LodGrid& grid, const NodeKey& chunk,
                LodItem* items, size_t count, const uint64_t* cellCounts, size_t cells,
                const LodParams& params, const uint8_t* tails = nullptr);

// Sorts items into canonical order: by code, then by the record's bytes, then by ref. freeBits: the low bits
// in which the codes may differ (the others are equal). For a cell's items, and for tests.
void sortItems(LodItem* items, size_t count, int freeBits, IndexScratch& scratch);

// Indexes chunks elsewhere than indexChunk's CPU code (the GPU: render/gpu_indexer.h) with the same
// result, byte for byte, and the same contract. Called from every indexing thread at once.
class ChunkIndexer {
public:
  virtual ~ChunkIndexer() = default;
  virtual void index(ChunkNodes& out, IndexScratch& scratch, const LodGrid& grid, const NodeKey& chunk,
                     LodItem* items, size_t count, const uint64_t* cellCounts, size_t cells,
                     const LodParams& params, const uint8_t* tails) = 0;
};

// The pieces another indexer needs to give indexChunk's result from its own sort and subsamples.
//
// The taken level of a point no subsample took: it stays in its leaf.
inline constexpr uint32_t kNotTakenLevel = 0xFFFFFFFFu;
// Items sorted by code alone, ties in any order, into the canonical order (lod_index.h's top): each run
// of equal codes sorted by record bytes and ref, `order` (each item's place in some other array) moved
// with its item. True when there was such a run (the order may have changed). Runs on all threads.
bool orderEqualCodes(LodItem* items, uint32_t* order, size_t count);
// The chunk's nodes from its items in canonical order and, for each, the level whose subsample took it
// (kNotTakenLevel: none) and the color it took (rgb[0] | rgb[1] << 16, rgb[2]; averaged where colors
// are filtered); marks the taken items as indexChunk does. The other arguments are indexChunk's.
void assembleIndexedChunk(ChunkNodes& out, const NodeKey& chunk, LodItem* items, size_t count,
                          const uint32_t* takenLevels, const uint32_t* colors, const LodParams& params,
                          const uint8_t* tails = nullptr);

} // namespace pointrast::lod
