#include "cloud/lod_index.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cassert>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

#include "base/parallel.h"

namespace pointrast::lod {

namespace {

inline uint64_t untagged(uint64_t code) {
  return code & ~kTakenBit;
}

inline bool itemLess(const LodItem& a, const LodItem& b) {
  if (a.code != b.code) return a.code < b.code;
  const int c = std::memcmp(&a.record, &b.record, sizeof(PointRecord));
  return c < 0 || (c == 0 && a.ref < b.ref);
}

void insertionSort(LodItem* a, size_t n) {
  for (size_t i = 1; i < n; ++i) {
    if (!itemLess(a[i], a[i - 1])) continue;
    const LodItem v = a[i];
    size_t j = i;
    for (; j > 0 && itemLess(v, a[j - 1]); --j)
      a[j] = a[j - 1];
    a[j] = v;
  }
}

constexpr size_t kInsertionSortItems = 24;

// Calls visit(c, begin, end) for each child c of a node whose sorted items are [begin, end) and that
// holds some of them: its range, in child order. childShift: 3 * (kCodeLevels - level - 1).
template <class Visit>
void forEachChild(const LodItem* items, size_t begin, size_t end, int childShift, Visit&& visit) {
  size_t childBegin = begin;
  for (int c = 0; c < 8 && childBegin < end; ++c) {
    const uint64_t childCell = untagged(items[childBegin].code) >> childShift;
    if ((childCell & 7) != uint64_t(c)) continue;
    const size_t childEnd = static_cast<size_t>(
        std::partition_point(items + childBegin, items + end,
                             [&](const LodItem& e) { return untagged(e.code) >> childShift == childCell; }) -
        items);
    visit(c, childBegin, childEnd);
    childBegin = childEnd;
  }
}

class Indexer {
public:
  Indexer(ChunkNodes& out, LodItem* items, const LodGrid& grid, const LodParams& params, const uint8_t* tails)
      : out_(out), items_(items), grid_(grid), params_(params), tails_(tails) {}

  // Subsamples the points of [begin, end) that reach a node at `level` into dst (see lod_index.h), and
  // their tails into dstTails (where points carry them).
  // left[c]: points of child c that remain after it, for the node's children.
  // dst has room for every point of [begin, end); returns the end of what was written.
  PointRecord* subsample(int level, size_t begin, size_t end, PointRecord* dst, uint8_t* dstTails,
                         uint64_t left[8]) {
    if (grid_.isotropic) return subsampleCells<true>(level, begin, end, dst, dstTails, left);
    return subsampleCells<false>(level, begin, end, dst, dstTails, left);
  }

  void copyTail(uint8_t* dstTails, size_t at, const LodItem& item) const {
    const uint32_t n = params_.tailBytes;
    std::memcpy(dstTails + at * n, tails_ + item.ref * n, n);
  }

  // One pass over the cells' runs: the point nearest each cell's center, the color sums, the count. A
  // cell's center is computed only when a second point reaches it: most cells of deep nodes hold one.
  template <bool kIsotropic>
  PointRecord* subsampleCells(int level, size_t begin, size_t end, PointRecord* dst, uint8_t* dstTails,
                              uint64_t left[8]) {
    PointRecord* const dst0 = dst;
    const int cellLevel = grid_.sampleLevel(level);
    const int shift = 3 * (kCodeLevels - cellLevel);
    const int childShift = 3 * (cellLevel - level - 1); // a cell's child index: (cell >> childShift) & 7
    using Distance = std::conditional_t<kIsotropic, uint64_t, double>;
    auto distance = [&](const LodGrid::Center& center, const PointRecord& r) -> Distance {
      if constexpr (kIsotropic)
        return grid_.centerDistanceIsotropic(center, r);
      else
        return grid_.centerDistance(center, r);
    };
    for (size_t i = begin; i < end;) {
      const uint64_t cell = untagged(items_[i].code) >> shift;
      size_t k = i;
      while (k < end && (items_[k].code & kTakenBit))
        ++k;
      if (k == end || untagged(items_[k].code) >> shift != cell) { // every point of the cell was taken
        while (k < end && untagged(items_[k].code) >> shift == cell)
          ++k;
        i = k;
        continue;
      }
      size_t best = k;
      const PointRecord& first = items_[k].record;
      uint64_t sum[3] = {first.rgb[0], first.rgb[1], first.rgb[2]}, reached = 1;
      LodGrid::Center center{};
      Distance bestDistance = 0;
      for (++k; k < end && untagged(items_[k].code) >> shift == cell; ++k) {
        if (items_[k].code & kTakenBit) continue;
        const PointRecord& r = items_[k].record;
        if (reached == 1) {
          center = grid_.cellCenter(cell, cellLevel);
          bestDistance = distance(center, items_[best].record);
        }
        const Distance d = distance(center, r);
        // Strictly nearer only: on a tie the first point in canonical order stays.
        const bool nearer = d < bestDistance;
        bestDistance = nearer ? d : bestDistance;
        best = nearer ? k : best;
        sum[0] += r.rgb[0];
        sum[1] += r.rgb[1];
        sum[2] += r.rgb[2];
        ++reached;
      }
      i = k;
      items_[best].code |= kTakenBit;
      *dst = items_[best].record;
      if (tails_) copyTail(dstTails, static_cast<size_t>(dst - dst0), items_[best]);
      if (params_.averageColors && reached > 1)
        for (int c = 0; c < 3; ++c)
          dst->rgb[c] = static_cast<uint16_t>((sum[c] + reached / 2) / reached);
      ++dst;
      left[(cell >> childShift) & 7] += reached - 1;
    }
    return dst;
  }

  // The subtree of the node at `level` whose cube's points are [begin, end) (at least one reaches it).
  // Its points go to records_[used_...), which has room for every point of the chunk.
  void node(int level, size_t begin, size_t end) {
    ChunkNodes::Node n;
    n.key = keyOfCode(items_[begin].code, level);
    n.first = used_;
    PointRecord* const start = out_.records.data() + used_;
    if (end - begin > params_.leafPoints && level < kMaxLevel) {
      uint64_t left[8] = {0, 0, 0, 0, 0, 0, 0, 0};
      n.count = static_cast<uint64_t>(subsample(level, begin, end, start, tailsAt(used_), left) - start);
      used_ += n.count;
      const int childShift = 3 * (kCodeLevels - level - 1);
      forEachChild(items_, begin, end, childShift, [&](int c, size_t childBegin, size_t childEnd) {
        if (left[c] > 0) node(level + 1, childBegin, childEnd);
      });
    } else {
      PointRecord* dst = start;
      uint8_t* const dstTails = tailsAt(used_);
      for (size_t k = begin; k < end; ++k)
        if (!(items_[k].code & kTakenBit)) {
          if (tails_) copyTail(dstTails, static_cast<size_t>(dst - start), items_[k]);
          *dst++ = items_[k].record;
        }
      n.count = static_cast<uint64_t>(dst - start);
      used_ += n.count;
    }
    assert(n.count > 0);
    out_.nodes.push_back(n);
  }

private:
  uint8_t* tailsAt(uint64_t record) {
    return tails_ ? out_.tails.data() + record * params_.tailBytes : nullptr;
  }

  ChunkNodes& out_;
  uint64_t used_ = 0;
  LodItem* items_;
  const LodGrid& grid_;
  const LodParams& params_;
  const uint8_t* tails_;
};

} // namespace

// Most significant digit first: one counting pass on the top bits that may differ (buckets of ~8
// items), then each bucket the same way; small buckets by insertion sort. Equal codes (copies of a point,
// or points closer than a code cell) fall through to a comparison sort on the record bytes.
void sortItems(LodItem* items, size_t count, int freeBits, IndexScratch& scratch) {
  if (count <= kInsertionSortItems) {
    insertionSort(items, count);
    return;
  }
  if (freeBits <= 0) {
    std::sort(items, items + count, itemLess);
    return;
  }
  const int bits = std::min(freeBits, std::clamp(int(std::bit_width(count)) - 3, 4, 12));
  const int shift = freeBits - bits;
  const uint64_t mask = (uint64_t(1) << bits) - 1;
  const size_t buckets = size_t(1) << bits;
  if (scratch.items.size() < count) scratch.items.resize(count);
  std::vector<uint64_t> start(buckets + 1, 0); // nested calls need their own counts
  for (size_t i = 0; i < count; ++i)
    ++start[((items[i].code >> shift) & mask) + 1];
  for (size_t b = 0; b < buckets; ++b)
    start[b + 1] += start[b];
  {
    std::vector<uint64_t>& next = scratch.counts;
    next.assign(start.begin(), start.end() - 1);
    LodItem* tmp = scratch.items.data();
    for (size_t i = 0; i < count; ++i)
      tmp[next[(items[i].code >> shift) & mask]++] = items[i];
    std::memcpy(static_cast<void*>(items), tmp, count * sizeof(LodItem));
  }
  for (size_t b = 0; b < buckets; ++b)
    if (start[b + 1] - start[b] > 1) sortItems(items + start[b], start[b + 1] - start[b], shift, scratch);
}

void indexChunk(ChunkNodes& out, IndexScratch& scratch, const LodGrid& grid, const NodeKey& chunk,
                LodItem* items, size_t count, const uint64_t* cellCounts, size_t cells,
                const LodParams& params, const uint8_t* tails) {
  assert((tails != nullptr) == (params.tailBytes > 0));
  assert(chunk.level >= 0 && chunk.level <= grid.countLevel());
  assert(cells == size_t(1) << 3 * (grid.countLevel() - chunk.level));
  out.chunk = chunk;
  out.topCounts.assign(static_cast<size_t>(chunk.level), 0);
  out.nodes.clear();
  if (count == 0) return;
  const int cellFreeBits = 3 * (kCodeLevels - grid.countLevel());
  size_t begin = 0;
  for (size_t c = 0; c < cells; ++c) {
    const size_t n = static_cast<size_t>(cellCounts[c]);
    if (n > 1) sortItems(items + begin, n, cellFreeBits, scratch);
    begin += n;
  }
  assert(begin == count);
  assert(keyOfCode(items[0].code, chunk.level) == chunk &&
         keyOfCode(items[count - 1].code, chunk.level) == chunk);

  // Room for every point, in buffers that keep their size from chunk to chunk (grown, never shrunk):
  // no zeroing per chunk. Nodes and topCounts say how much of them is in use.
  if (out.records.size() < count) out.records.resize(count);
  if (out.top.size() < count) out.top.resize(count);
  const size_t tailBytes = size_t(count) * params.tailBytes;
  if (out.tails.size() < tailBytes) out.tails.resize(tailBytes);
  if (out.topTails.size() < tailBytes) out.topTails.resize(tailBytes);
  Indexer indexer(out, items, grid, params, tails);
  uint64_t taken = 0, unused[8];
  PointRecord* top = out.top.data();
  for (int level = 0; level < chunk.level; ++level) {
    uint8_t* const topTails =
        tails ? out.topTails.data() + (top - out.top.data()) * params.tailBytes : nullptr;
    PointRecord* const levelEnd = indexer.subsample(level, 0, count, top, topTails, unused);
    out.topCounts[static_cast<size_t>(level)] = static_cast<uint64_t>(levelEnd - top);
    taken += out.topCounts[static_cast<size_t>(level)];
    top = levelEnd;
  }
  if (taken < count) indexer.node(chunk.level, 0, count);
}

namespace {

// indexChunk's node walk over another indexer's result: the same nodes in the same order, the same
// records (a taken point with the color it took), the same tails.
class IndexedAssembler {
public:
  IndexedAssembler(ChunkNodes& out, const LodItem* items, const uint32_t* levels, const uint32_t* colors,
                   const LodParams& params, const uint8_t* tails)
      : out_(out), items_(items), levels_(levels), colors_(colors), params_(params), tails_(tails) {}

  void put(PointRecord* dst, uint8_t* dstTails, size_t at, size_t k, bool taken) const {
    dst[at] = items_[k].record;
    if (taken) {
      dst[at].rgb[0] = static_cast<uint16_t>(colors_[2 * k] & 0xFFFFu);
      dst[at].rgb[1] = static_cast<uint16_t>(colors_[2 * k] >> 16);
      dst[at].rgb[2] = static_cast<uint16_t>(colors_[2 * k + 1] & 0xFFFFu);
    }
    if (tails_) {
      const uint32_t n = params_.tailBytes;
      std::memcpy(dstTails + at * n, tails_ + items_[k].ref * n, n);
    }
  }

  void node(int level, size_t begin, size_t end) {
    ChunkNodes::Node n;
    n.key = keyOfCode(items_[begin].code, level);
    n.first = used_;
    PointRecord* const start = out_.records.data() + used_;
    uint8_t* const startTails = tails_ ? out_.tails.data() + used_ * params_.tailBytes : nullptr;
    size_t written = 0;
    if (end - begin > params_.leafPoints && level < kMaxLevel) {
      const int childShift = 3 * (kCodeLevels - level - 1);
      uint64_t left[8] = {0, 0, 0, 0, 0, 0, 0, 0};
      const uint32_t here = static_cast<uint32_t>(level);
      for (size_t k = begin; k < end; ++k) {
        const uint32_t taken = levels_[k];
        if (taken == here)
          put(start, startTails, written++, k, true);
        else if (taken > here) // kNotTakenLevel included
          ++left[(untagged(items_[k].code) >> childShift) & 7];
      }
      n.count = written;
      used_ += written;
      forEachChild(items_, begin, end, childShift, [&](int c, size_t childBegin, size_t childEnd) {
        if (left[c] > 0) node(level + 1, childBegin, childEnd);
      });
    } else {
      for (size_t k = begin; k < end; ++k)
        if (levels_[k] == kNotTakenLevel) put(start, startTails, written++, k, false);
      n.count = written;
      used_ += written;
    }
    assert(n.count > 0);
    out_.nodes.push_back(n);
  }

private:
  ChunkNodes& out_;
  uint64_t used_ = 0;
  const LodItem* items_;
  const uint32_t* levels_;
  const uint32_t* colors_;
  const LodParams& params_;
  const uint8_t* tails_;
};

} // namespace

bool orderEqualCodes(LodItem* items, uint32_t* order, size_t count) {
  // In blocks on all threads, each a whole number of runs: the blocks' bounds first, moved forward to the
  // next run's start (read before any thread writes).
  const size_t kBlock = size_t(1) << 18;
  std::vector<size_t> bounds{0};
  for (size_t b = kBlock; b < count; b += kBlock) {
    size_t i = std::max(b, bounds.back());
    while (i < count && untagged(items[i].code) == untagged(items[i - 1].code))
      ++i;
    if (i < count && i > bounds.back()) bounds.push_back(i);
  }
  bounds.push_back(count);
  std::atomic<bool> any{false};
  parallelBlocks(bounds.size() - 1, 1, [&](uint64_t block, uint64_t, uint64_t) {
    std::vector<uint32_t> places;
    std::vector<LodItem> runItems;
    std::vector<uint32_t> runOrder;
    for (size_t i = bounds[block], end = bounds[block + 1]; i < end;) {
      size_t stop = i + 1;
      while (stop < end && untagged(items[stop].code) == untagged(items[i].code))
        ++stop;
      if (stop - i > 1) {
        any.store(true, std::memory_order_relaxed);
        // Sort the run's positions by their items, then move items and order along.
        const size_t n = stop - i;
        places.resize(n);
        for (size_t k = 0; k < n; ++k)
          places[k] = static_cast<uint32_t>(k);
        std::sort(places.begin(), places.end(),
                  [&](uint32_t a, uint32_t b) { return itemLess(items[i + a], items[i + b]); });
        runItems.resize(n);
        runOrder.resize(n);
        for (size_t k = 0; k < n; ++k) {
          runItems[k] = items[i + places[k]];
          runOrder[k] = order[i + places[k]];
        }
        std::copy(runItems.begin(), runItems.end(), items + i);
        std::copy(runOrder.begin(), runOrder.end(), order + i);
      }
      i = stop;
    }
  });
  return any.load();
}

void assembleIndexedChunk(ChunkNodes& out, const NodeKey& chunk, LodItem* items, size_t count,
                          const uint32_t* takenLevels, const uint32_t* colors, const LodParams& params,
                          const uint8_t* tails) {
  assert((tails != nullptr) == (params.tailBytes > 0));
  out.chunk = chunk;
  out.topCounts.assign(static_cast<size_t>(chunk.level), 0);
  out.nodes.clear();
  if (count == 0) return;
  if (out.records.size() < count) out.records.resize(count);
  if (out.top.size() < count) out.top.resize(count);
  const size_t tailBytes = size_t(count) * params.tailBytes;
  if (out.tails.size() < tailBytes) out.tails.resize(tailBytes);
  if (out.topTails.size() < tailBytes) out.topTails.resize(tailBytes);

  // The ancestors' subsamples, level after level, each in sorted order.
  const uint32_t levels = static_cast<uint32_t>(chunk.level);
  for (size_t k = 0; k < count; ++k)
    if (takenLevels[k] < levels) ++out.topCounts[takenLevels[k]];
  std::vector<uint64_t> at(levels + 1, 0);
  for (uint32_t l = 0; l < levels; ++l)
    at[l + 1] = at[l] + out.topCounts[l];
  IndexedAssembler assembler(out, items, takenLevels, colors, params, tails);
  for (size_t k = 0; k < count; ++k)
    if (takenLevels[k] < levels)
      assembler.put(out.top.data(), tails ? out.topTails.data() : nullptr, at[takenLevels[k]]++, k, true);
  if (at[levels] < count) assembler.node(chunk.level, 0, count);
  for (size_t k = 0; k < count; ++k)
    if (takenLevels[k] != kNotTakenLevel) items[k].code |= kTakenBit;
}

} // namespace pointrast::lod
