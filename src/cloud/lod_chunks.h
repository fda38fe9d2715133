// Chunks: the cells of the cube that the builder sorts and indexes on their own, on all cores, in memory
// or from temporary files (PotreeConverter's "count" and "chunk" phases). A histogram of the points over
// the cells of one level (countLevel, at most 8^7 cells) gives every coarser cell's count by prefix sums;
// a chunk is a largest cell holding at most chunkLimit points, or a single histogram cell where even that
// holds more. Chunks never change the octree (it is defined by the points alone): they only decide how
// the work is cut.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cloud/lod_grid.h"

namespace pointrast::lod {

struct LodChunk {
  NodeKey key;            // the chunk's cell, at most at countLevel
  uint64_t points = 0;    // input points in the cell
  uint64_t firstCell = 0; // its histogram cells [firstCell, endCell), Morton indices at countLevel
  uint64_t endCell = 0;
};

// Adds the histogram cells (grid.countLevel()) of records to counts (8^countLevel entries) with atomic
// additions, so several threads may count at once. A run of points in one cell costs one addition.
void countCells(uint64_t* counts, const LodGrid& grid, const PointRecord* records, size_t count);

// The chunks of a histogram, in Morton order (which is the order their nodes are written in). Empty cells
// give no chunk. chunkLimit >= 1.
std::vector<LodChunk> planChunks(const std::vector<uint64_t>& counts, int countLevel, uint64_t chunkLimit);

// For each histogram cell, the index of the chunk whose cell contains it (UINT32_MAX for cells outside
// every chunk, which hold no points).
std::vector<uint32_t> chunkOfCell(const std::vector<LodChunk>& chunks, int countLevel);

} // namespace pointrast::lod
