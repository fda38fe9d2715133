#include "cloud/lod_index.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cstring>
#include <limits>

namespace pointrast::lod {

namespace {

using Entry = IndexScratch::Entry;

// Canonical order: a counting sort on the code's top bits below the chunk's level, then each bucket
// sorted by (code, record bytes). Buckets average ~8 points, so the comparison sorts stay in L1.
void sortChunk(IndexScratch& s, const LodGrid& grid, int chunkLevel, const PointRecord* records, size_t n) {
  const int freeBits = 3 * (kCodeLevels - chunkLevel);
  const int bucketBits = std::clamp(int(std::bit_width(n)) - 3, 0, std::min(16, freeBits));
  const int shift = freeBits - bucketBits;
  const uint64_t mask = (uint64_t(1) << bucketBits) - 1;
  s.buckets.assign((size_t(1) << bucketBits) + 1, 0);
  for (size_t i = 0; i < n; ++i)
    ++s.buckets[((grid.code(records[i]) >> shift) & mask) + 1];
  for (size_t b = 1; b < s.buckets.size(); ++b)
    s.buckets[b] += s.buckets[b - 1];
  s.entries.resize(n);
  {
    std::vector<uint64_t> next(s.buckets.begin(), s.buckets.end() - 1);
    for (size_t i = 0; i < n; ++i) {
      const uint64_t code = grid.code(records[i]);
      s.entries[next[(code >> shift) & mask]++] = {code, i};
    }
  }
  auto less = [records](const Entry& a, const Entry& b) {
    if (a.code != b.code) return a.code < b.code;
    return std::memcmp(&records[a.index], &records[b.index], sizeof(PointRecord)) < 0;
  };
  for (size_t b = 0; b + 1 < s.buckets.size(); ++b)
    if (s.buckets[b + 1] - s.buckets[b] > 1)
      std::sort(s.entries.begin() + ptrdiff_t(s.buckets[b]), s.entries.begin() + ptrdiff_t(s.buckets[b + 1]),
                less);
  s.sorted.resize(n);
  for (size_t i = 0; i < n; ++i)
    s.sorted[i] = records[s.entries[i].index];
}

inline uint64_t untagged(uint64_t code) {
  return code & ~kTakenBit;
}

class Indexer {
public:
  Indexer(ChunkNodes& out, IndexScratch& s, const LodGrid& grid, const LodParams& params)
      : out_(out), entries_(s.entries.data()), records_(s.sorted.data()), grid_(grid), params_(params) {}

  // Subsamples the points of [begin, end) that reach a node at `level` into dst (see lod_index.h).
  // left[c]: points of child c that remain after it, for the node's children.
  void subsample(int level, size_t begin, size_t end, std::vector<PointRecord>& dst, uint64_t left[8]) {
    const int cellLevel = grid_.sampleLevel(level);
    const int shift = 3 * (kCodeLevels - cellLevel);
    const int childShift = 3 * (cellLevel - level - 1); // a cell's child index: (cell >> childShift) & 7
    const double cellSize = double(uint64_t(1) << (kCodeLevels - cellLevel)); // in code units
    for (size_t i = begin; i < end;) {
      const uint64_t cell = untagged(entries_[i].code) >> shift;
      const double center[3] = {(detail::compactBits3(cell >> 2) + 0.5) * cellSize,
                                (detail::compactBits3(cell >> 1) + 0.5) * cellSize,
                                (detail::compactBits3(cell) + 0.5) * cellSize};
      size_t best = end;
      double bestDistance = std::numeric_limits<double>::infinity();
      uint64_t sum[3] = {0, 0, 0}, reached = 0;
      size_t k = i;
      for (; k < end && untagged(entries_[k].code) >> shift == cell; ++k) {
        if (entries_[k].code & kTakenBit) continue;
        const PointRecord& r = records_[k];
        double u[3];
        grid_.codeSpace(r, u);
        const double d = (u[0] - center[0]) * (u[0] - center[0]) + (u[1] - center[1]) * (u[1] - center[1]) +
                         (u[2] - center[2]) * (u[2] - center[2]);
        if (d < bestDistance) {
          bestDistance = d;
          best = k;
        }
        sum[0] += r.rgb[0];
        sum[1] += r.rgb[1];
        sum[2] += r.rgb[2];
        ++reached;
      }
      i = k;
      if (reached == 0) continue;
      entries_[best].code |= kTakenBit;
      PointRecord pick = records_[best];
      if (params_.averageColors)
        for (int c = 0; c < 3; ++c)
          pick.rgb[c] = static_cast<uint16_t>((sum[c] + reached / 2) / reached);
      dst.push_back(pick);
      if (left) left[(cell >> childShift) & 7] += reached - 1;
    }
  }

  // The subtree of the node at `level` whose cube's points are [begin, end) (at least one reaches it).
  void node(int level, size_t begin, size_t end) {
    ChunkNodes::Node n;
    n.key = keyOfCode(entries_[begin].code, level);
    n.first = out_.records.size();
    if (end - begin > params_.leafPoints && level < kMaxLevel) {
      uint64_t left[8] = {0, 0, 0, 0, 0, 0, 0, 0};
      subsample(level, begin, end, out_.records, left);
      n.count = out_.records.size() - n.first;
      const int childShift = 3 * (kCodeLevels - level - 1);
      size_t childBegin = begin;
      for (int c = 0; c < 8 && childBegin < end; ++c) {
        const uint64_t childCell = untagged(entries_[childBegin].code) >> childShift;
        if ((childCell & 7) != uint64_t(c)) continue;
        const size_t childEnd =
            static_cast<size_t>(std::partition_point(entries_ + childBegin, entries_ + end,
                                                     [&](const Entry& e) {
                                                       return untagged(e.code) >> childShift == childCell;
                                                     }) -
                                entries_);
        if (left[c] > 0) node(level + 1, childBegin, childEnd);
        childBegin = childEnd;
      }
    } else {
      for (size_t k = begin; k < end; ++k)
        if (!(entries_[k].code & kTakenBit)) out_.records.push_back(records_[k]);
      n.count = out_.records.size() - n.first;
    }
    assert(n.count > 0);
    out_.nodes.push_back(n);
  }

private:
  ChunkNodes& out_;
  Entry* entries_;
  const PointRecord* records_;
  const LodGrid& grid_;
  const LodParams& params_;
};

} // namespace

void indexChunk(ChunkNodes& out, IndexScratch& scratch, const LodGrid& grid, const NodeKey& chunk,
                const PointRecord* records, size_t count, const LodParams& params) {
  assert(chunk.level >= 0 && chunk.level <= grid.countLevel());
  out.chunk = chunk;
  out.top.clear();
  out.topCounts.assign(static_cast<size_t>(chunk.level), 0);
  out.nodes.clear();
  out.records.clear();
  if (count == 0) return;
  sortChunk(scratch, grid, chunk.level, records, count);
  assert(keyOfCode(scratch.entries.front().code, chunk.level) == chunk &&
         keyOfCode(scratch.entries.back().code, chunk.level) == chunk);

  out.records.reserve(count);
  Indexer indexer(out, scratch, grid, params);
  uint64_t taken = 0;
  for (int level = 0; level < chunk.level; ++level) {
    const size_t before = out.top.size();
    indexer.subsample(level, 0, count, out.top, nullptr);
    out.topCounts[static_cast<size_t>(level)] = out.top.size() - before;
    taken += out.top.size() - before;
  }
  if (taken < count) indexer.node(chunk.level, 0, count);
}

} // namespace pointrast::lod
