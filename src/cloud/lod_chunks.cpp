#include "cloud/lod_chunks.h"

#include <atomic>
#include <cassert>

namespace pointrast::lod {

void countCells(uint64_t* counts, const LodGrid& grid, const PointRecord* records, size_t count) {
  uint64_t run = 0, cell = 0;
  for (size_t i = 0; i < count; ++i) {
    const uint64_t c = grid.countCell(records[i]);
    if (run && c != cell) {
      std::atomic_ref<uint64_t>(counts[cell]).fetch_add(run, std::memory_order_relaxed);
      run = 0;
    }
    cell = c;
    ++run;
  }
  if (run) std::atomic_ref<uint64_t>(counts[cell]).fetch_add(run, std::memory_order_relaxed);
}

std::vector<LodChunk> planChunks(const std::vector<uint64_t>& counts, int countLevel, uint64_t chunkLimit) {
  assert(countLevel >= 0 && countLevel <= kMaxCountLevel && chunkLimit >= 1);
  assert(counts.size() == uint64_t(1) << 3 * countLevel);
  // prefix[i] = points in cells [0, i): a cell at level l is the histogram range
  // [index << 3(countLevel - l), (index + 1) << 3(countLevel - l)).
  std::vector<uint64_t> prefix(counts.size() + 1, 0);
  for (size_t i = 0; i < counts.size(); ++i)
    prefix[i + 1] = prefix[i] + counts[i];

  std::vector<LodChunk> chunks;
  struct Cell {
    int level;
    uint64_t index;
  };
  // Depth-first with children pushed in reverse, so chunks come out in Morton order.
  std::vector<Cell> stack{{0, 0}};
  while (!stack.empty()) {
    const Cell cell = stack.back();
    stack.pop_back();
    const int shift = 3 * (countLevel - cell.level);
    const uint64_t first = cell.index << shift, end = (cell.index + 1) << shift;
    const uint64_t points = prefix[end] - prefix[first];
    if (points == 0) continue;
    if (points <= chunkLimit || cell.level == countLevel) {
      LodChunk chunk;
      chunk.key = keyOfCode(cell.index << 3 * (kCodeLevels - cell.level), cell.level);
      chunk.points = points;
      chunk.firstCell = first;
      chunk.endCell = end;
      chunks.push_back(chunk);
      continue;
    }
    for (int child = 7; child >= 0; --child)
      stack.push_back({cell.level + 1, cell.index << 3 | uint64_t(child)});
  }
  return chunks;
}

std::vector<uint32_t> chunkOfCell(const std::vector<LodChunk>& chunks, int countLevel) {
  std::vector<uint32_t> table(size_t(1) << 3 * countLevel, UINT32_MAX);
  for (size_t c = 0; c < chunks.size(); ++c)
    for (uint64_t cell = chunks[c].firstCell; cell < chunks[c].endCell; ++cell)
      table[cell] = static_cast<uint32_t>(c);
  return table;
}

} // namespace pointrast::lod
