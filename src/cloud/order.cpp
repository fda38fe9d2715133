// Vertex orders of "Rendering Point Clouds with Compute Shaders and Vertex Order Optimization"
// (Schuetz, Kerbl, Wimmer 2021), section 4: original, Morton, shuffled and shuffled Morton.
//
// Every order is a sort of the point indices by a 64-bit key with ties broken by index, so results are
// deterministic and independent of the thread count:
//   Morton         key = 63-bit Morton code (Z-order) over the cubic bounds
//   Shuffled       key = the i-th output of splitmix64 seeded with `seed` (Steele, Lea, Flood, "Fast
//                  splittable pseudorandom number generators", OOPSLA 2014); distinct for distinct i
//                  because its mixing function is a bijection, so sorting by it is a random permutation
//   ShuffledMorton Morton order, then its runs of kShuffleRun points sorted by the splitmix64 key of
//                  the run index (the paper's "shuffled Morton": local patches kept, patches scattered)
//
// The sort (sortByKey) is a parallel sample sort (splitters from a regular sample, one counting and one
// scattering pass into ~4096 buckets, then an LSD radix sort inside each bucket) that needs little more
// memory than its output: keys are recomputed from the points instead of stored, so computeOrder costs
// the order itself (8 B/point), a 2 B/point bucket id while it runs, and per-thread buckets of a few MB.
// (Morton: G. M. Morton, "A computer oriented geodetic data base and a new technique in file
// sequencing", IBM, 1966.)
#include "cloud/order.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>

#include "base/error.h"
#include "base/parallel.h"
#include "cloud/detail.h"

namespace pointrast {

namespace {

constexpr const char* kOrderNames[] = {"original", "morton", "shuffled", "shuffled-morton"};

using detail::compactBits3;
using detail::splitmixAt;
using detail::spreadBits3;

// ---- parallel sample sort of indices by (key(i), i) --------------------------------------------------

struct KeyIndex {
  uint64_t key;
  uint64_t index;
};

// Stable LSD radix sort of a by key, 8 bits per pass, skipping the bits all keys share and the passes
// whose digit is constant. b is scratch of the same size; the result ends in a.
void radixSortPairs(std::vector<KeyIndex>& a, std::vector<KeyIndex>& b) {
  const size_t n = a.size();
  if (n < 2) return;
  uint64_t lo = ~0ull, hi = 0;
  for (const KeyIndex& p : a) {
    lo = std::min(lo, p.key);
    hi = std::max(hi, p.key);
  }
  if (lo == hi) return;
  const int bits = 64 - std::countl_zero(lo ^ hi); // keys agree above this bit
  const int passes = (bits + 7) / 8;
  std::vector<uint64_t> count(size_t(passes) * 256, 0);
  for (const KeyIndex& p : a)
    for (int d = 0; d < passes; ++d)
      ++count[d * 256 + ((p.key >> (8 * d)) & 255)];
  b.resize(n);
  for (int d = 0; d < passes; ++d) {
    uint64_t* c = count.data() + d * 256;
    if (c[(a[0].key >> (8 * d)) & 255] == n) continue; // digit constant: the pass would not move anything
    uint64_t sum = 0;
    for (int k = 0; k < 256; ++k) {
      uint64_t t = c[k];
      c[k] = sum;
      sum += t;
    }
    for (const KeyIndex& p : a)
      b[c[(p.key >> (8 * d)) & 255]++] = p;
    a.swap(b);
  }
}

// Bucket lookup over sorted, distinct splitters. A key equal to a splitter that is frequent in the
// sample gets its own bucket, so a value repeated millions of times (duplicate points) ends in a bucket
// that needs no sorting instead of swelling a mixed one. A table over the top 16 key bits narrows the
// search to the splitters sharing those bits (usually zero to two), so a lookup costs about one L2 hit
// instead of a 12-step binary search; clustered keys still get a correct, if longer, search.
class Buckets {
public:
  // keyBits: keys are < 2^keyBits (63 for Morton codes, 64 for random keys).
  Buckets(std::vector<uint64_t> sample, size_t target, int keyBits) : shift_(keyBits - kTableBits) {
    std::sort(sample.begin(), sample.end());
    const size_t m = sample.size();
    const size_t heavy = std::max<size_t>(2, m / target / 2);
    for (size_t k = 1; k < target; ++k) {
      uint64_t s = sample[k * m / target];
      if (!splitters_.empty() && splitters_.back() == s) continue;
      auto [b, e] = std::equal_range(sample.begin(), sample.end(), s);
      splitters_.push_back(s);
      heavy_.push_back(size_t(e - b) >= heavy);
    }
    count_ = splitters_.size();
    table_.resize((size_t(1) << kTableBits) + 1);
    size_t j = 0;
    for (size_t p = 0; p < (size_t(1) << kTableBits); ++p) {
      while (j < count_ && (splitters_[j] >> shift_) < p)
        ++j;
      table_[p] = static_cast<uint16_t>(j);
    }
    table_.back() = static_cast<uint16_t>(count_);
  }
  size_t size() const { return 2 * count_ + 1; }
  size_t operator()(uint64_t key) const {
    const size_t p = static_cast<size_t>(key >> shift_);
    size_t j = table_[p], len = table_[p + 1] - j; // j = number of splitters < key, somewhere in here
    while (len > 0) {
      size_t half = len / 2;
      if (splitters_[j + half] < key) {
        j += half + 1;
        len -= half + 1;
      } else {
        len = half;
      }
    }
    return 2 * j + (j < count_ && heavy_[j] && splitters_[j] == key ? 1 : 0);
  }

private:
  static constexpr int kTableBits = 16;
  int shift_;
  std::vector<uint64_t> splitters_;
  std::vector<uint8_t> heavy_;
  std::vector<uint16_t> table_; // table_[p] = number of splitters whose top bits are < p
  size_t count_ = 0;
};

// Per-thread bucket buffers, reused across the buckets a worker sorts (fresh allocations would fault in
// new pages for every bucket).
struct Scratch {
  std::vector<KeyIndex> a, b;
};
thread_local Scratch tScratch;

// order[0..n) = indices sorted by (key(i), i). key must be a pure function of i.
template <class Key> void sortByKey(uint64_t* order, uint64_t n, const Key& key) {
  // Below this a single sort is faster than setting up buckets.
  constexpr uint64_t kSerialBelow = uint64_t(1) << 16;
  if (n < kSerialBelow) {
    std::vector<KeyIndex> a(n), b;
    for (uint64_t i = 0; i < n; ++i)
      a[i] = {key(i), i};
    radixSortPairs(a, b);
    for (uint64_t i = 0; i < n; ++i)
      order[i] = a[i].index;
    return;
  }
  // Up to 4096 buckets of >= 4096 points: ~250 k points (8 MB of scratch per thread) at a billion.
  const size_t target = static_cast<size_t>(std::clamp<uint64_t>(n / 4096, 64, 4096));
  const uint64_t sampleSize = std::min<uint64_t>(n, uint64_t(64) * target);
  std::vector<uint64_t> sample(sampleSize);
  parallelBlocks(sampleSize, 4096, [&](uint64_t, uint64_t begin, uint64_t end) {
    for (uint64_t j = begin; j < end; ++j)
      sample[j] = key(j * n / sampleSize); // j * n < 2^58
  });
  const Buckets bucketOf(std::move(sample), target, Key::kBits);
  const size_t buckets = bucketOf.size();

  // At most 256 blocks, so per-block counters stay small (256 x 8191 x 8 B = 16 MB at most).
  const uint64_t blockSize = std::max<uint64_t>(uint64_t(1) << 16, (n + 255) / 256);
  const uint64_t blocks = (n + blockSize - 1) / blockSize;
  std::vector<uint64_t> offset(blocks * buckets, 0);
  // Each point's bucket, kept between the counting and the scattering pass (2 B/point, < 8191 buckets)
  // so the key and the search run once per point.
  std::vector<uint16_t> bucketId(n);
  parallelBlocks(n, blockSize, [&](uint64_t block, uint64_t begin, uint64_t end) {
    uint64_t* c = offset.data() + block * buckets;
    for (uint64_t i = begin; i < end; ++i) {
      const size_t b = bucketOf(key(i));
      bucketId[i] = static_cast<uint16_t>(b);
      ++c[b];
    }
  });
  // Bucket-major, block-minor prefix sums: each bucket receives its indices in ascending order.
  std::vector<uint64_t> bucketStart(buckets + 1, 0);
  uint64_t sum = 0;
  for (size_t k = 0; k < buckets; ++k) {
    bucketStart[k] = sum;
    for (uint64_t b = 0; b < blocks; ++b) {
      uint64_t t = offset[b * buckets + k];
      offset[b * buckets + k] = sum;
      sum += t;
    }
  }
  bucketStart[buckets] = sum;
  parallelBlocks(n, blockSize, [&](uint64_t block, uint64_t begin, uint64_t end) {
    uint64_t* c = offset.data() + block * buckets;
    for (uint64_t i = begin; i < end; ++i)
      order[c[bucketId[i]]++] = i;
  });
  std::vector<uint16_t>().swap(bucketId);

  // Sort inside buckets, largest first for load balance.
  std::vector<uint32_t> byCount(buckets);
  for (size_t k = 0; k < buckets; ++k)
    byCount[k] = static_cast<uint32_t>(k);
  std::stable_sort(byCount.begin(), byCount.end(), [&](uint32_t a, uint32_t b) {
    return bucketStart[a + 1] - bucketStart[a] > bucketStart[b + 1] - bucketStart[b];
  });
  parallelBlocks(buckets, 1, [&](uint64_t job, uint64_t, uint64_t) {
    std::vector<KeyIndex>& a = tScratch.a;
    std::vector<KeyIndex>& b = tScratch.b;
    const uint32_t k = byCount[job];
    const uint64_t begin = bucketStart[k], end = bucketStart[k + 1];
    if (end - begin < 2 || (k & 1)) return; // odd buckets hold one key value, already in index order
    a.resize(end - begin);
    // The bucket's points are scattered over the cloud: prefetch a few ahead to overlap the misses.
    constexpr uint64_t kAhead = 16;
    for (uint64_t i = begin; i < end; ++i) {
      if (i + kAhead < end) key.prefetch(order[i + kAhead]);
      a[i - begin] = {key(order[i]), order[i]};
    }
    radixSortPairs(a, b); // stable, and the indices arrived ascending: ties stay in index order
    for (uint64_t i = begin; i < end; ++i)
      order[i] = a[i - begin].index;
  });
  tScratch = {}; // the calling thread was one of the workers: give its buffers back
}

// Maps quantized positions to 21-bit cells of the cubic bounds.
struct MortonKey {
  static constexpr int kBits = 63;
  const int32_t* positions;
  int64_t ref[3]; // quantized coordinate of the cube's corner on each axis
  double mul[3];  // cells per quantization step (signed with the axis scale)

  MortonKey(const PointCloud& cloud) : positions(cloud.positions.data()) {
    detail::QuantBox box = detail::quantBoxParallel(cloud.positions.data(), cloud.size());
    const double s[3] = {cloud.scale.x, cloud.scale.y, cloud.scale.z};
    double cube = 0;
    for (int a = 0; a < 3; ++a)
      if (!box.empty()) cube = std::max(cube, double(int64_t(box.max[a]) - box.min[a]) * std::abs(s[a]));
    // The largest extent on all axes: cells are cubes, so Morton order treats the axes alike.
    const double cellsPerUnit = cube > 0 ? double(1 << 21) / cube : 0.0;
    for (int a = 0; a < 3; ++a) {
      ref[a] = s[a] >= 0 ? box.min[a] : box.max[a];
      // With a negative scale, (q - max) * negative >= 0. A subnormal cube (a file's subnormal scale)
      // makes cellsPerUnit infinite and (q - ref) * mul NaN at the corner: then divide by the cube first.
      mul[a] = std::isfinite(cellsPerUnit) ? s[a] * cellsPerUnit : s[a] / cube * double(1 << 21);
    }
  }
  uint64_t operator()(uint64_t i) const {
    const int32_t* p = positions + 3 * i;
    uint32_t c[3];
    for (int a = 0; a < 3; ++a) {
      double cell = double(p[a] - ref[a]) * mul[a];
      // The far face maps to 2^21 - 1. NaN (0 x infinity: an axis of zero extent whose scale is huge
      // next to the cube) to 0, as no integer holds it.
      c[a] = cell > 0 ? static_cast<uint32_t>(std::min(cell, double((1 << 21) - 1))) : 0;
    }
    return spreadBits3(c[0]) | spreadBits3(c[1]) << 1 | spreadBits3(c[2]) << 2; // = mortonCode()
  }
  void prefetch(uint64_t i) const { __builtin_prefetch(positions + 3 * i); }
};

// Maps particle centers to the cells of a 1024^3 grid over the set's center bounds (spatialOrder).
struct ParticleCellKey {
  static constexpr int kBits = 30;
  const float* xyz;
  double lo[3], cellsPerUnit[3];

  ParticleCellKey(const ParticleSet& set) : xyz(set.xyz.data()) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = set.bounds.min[a] - set.origin[a]; // where the floats are: relative to the origin
      cellsPerUnit[a] = 1024.0 / std::max(set.bounds.max[a] - set.bounds.min[a], 1e-30);
    }
  }
  uint64_t operator()(uint64_t i) const {
    uint32_t c[3];
    for (int a = 0; a < 3; ++a) {
      const double q = (double(xyz[3 * i + a]) - lo[a]) * cellsPerUnit[a];
      c[a] = q >= 0 && q < 1024 ? uint32_t(q) : (q >= 1024 ? 1023u : 0u); // NaN: 0
    }
    return spreadBits3(c[0]) | spreadBits3(c[1]) << 1 | spreadBits3(c[2]) << 2;
  }
  void prefetch(uint64_t i) const { __builtin_prefetch(xyz + 3 * i); }
};

struct ShuffleKey {
  static constexpr int kBits = 64;
  uint64_t seed;
  uint64_t operator()(uint64_t i) const { return splitmixAt(seed, i); }
  void prefetch(uint64_t) const {}
};

} // namespace

Order parseOrder(std::string_view name) {
  for (int k = 0; k < 4; ++k)
    if (name == kOrderNames[k]) return static_cast<Order>(k);
  throw InputError("unknown order '" + std::string(name) +
                   "' (choices: original, morton, shuffled, shuffled-morton)");
}

const char* orderName(Order order) {
  return kOrderNames[static_cast<int>(order)];
}

uint64_t mortonCode(uint32_t x, uint32_t y, uint32_t z) {
  assert(x < (1u << 21) && y < (1u << 21) && z < (1u << 21));
  // bit:  ... 8  7  6  5  4  3  2  1  0
  //       ... z2 y2 x2 z1 y1 x1 z0 y0 x0
  return spreadBits3(x) | spreadBits3(y) << 1 | spreadBits3(z) << 2;
}

void mortonDecode(uint64_t code, uint32_t& x, uint32_t& y, uint32_t& z) {
  x = compactBits3(code);
  y = compactBits3(code >> 1);
  z = compactBits3(code >> 2);
}

void computeOrder(std::vector<uint64_t>& order, const PointCloud& cloud, Order kind, uint64_t seed) {
  const uint64_t n = cloud.size();
  order.resize(n);
  switch (kind) {
  case Order::Original:
    parallelBlocks(n, uint64_t(1) << 20, [&](uint64_t, uint64_t begin, uint64_t end) {
      for (uint64_t i = begin; i < end; ++i)
        order[i] = i;
    });
    return;
  case Order::Morton:
    sortByKey(order.data(), n, MortonKey(cloud));
    return;
  case Order::Shuffled:
    sortByKey(order.data(), n, ShuffleKey{seed});
    return;
  case Order::ShuffledMorton: {
    if (n == 0) return;
    sortByKey(order.data(), n, MortonKey(cloud));
    const uint64_t runs = (n + kShuffleRun - 1) / kShuffleRun;
    std::vector<uint64_t> runOrder(runs);
    sortByKey(runOrder.data(), runs, ShuffleKey{seed});
    const uint64_t lastRun = runs - 1, lastLength = n - lastRun * kShuffleRun;
    uint64_t lastAt = 0; // where the (possibly short) last run lands; runs after it start earlier
    for (uint64_t p = 0; p < runs; ++p)
      if (runOrder[p] == lastRun) lastAt = p;
    std::vector<uint64_t> morton(order);
    parallelBlocks(runs, 4096, [&](uint64_t, uint64_t begin, uint64_t end) {
      for (uint64_t p = begin; p < end; ++p) {
        const uint64_t r = runOrder[p];
        const uint64_t length = r == lastRun ? lastLength : kShuffleRun;
        const uint64_t dst = p * kShuffleRun - (p > lastAt ? kShuffleRun - lastLength : 0);
        std::copy_n(morton.data() + r * kShuffleRun, length, order.data() + dst);
      }
    });
    return;
  }
  }
}

namespace {
// out = data permuted by order (kPer values a point); nothing for an empty array.
template <class T, size_t kPer>
void gatherInto(std::vector<T>& out, const std::vector<T>& data, const std::vector<uint64_t>& order) {
  out.clear();
  if (data.empty()) return;
  const uint64_t n = order.size();
  assert(data.size() == n * kPer && "attribute array length differs from the point count");
  out.resize(data.size());
  parallelBlocks(n, uint64_t(1) << 18, [&](uint64_t, uint64_t begin, uint64_t end) {
    for (uint64_t i = begin; i < end; ++i)
      for (size_t k = 0; k < kPer; ++k)
        out[i * kPer + k] = data[order[i] * kPer + k];
  });
}

template <class T, size_t kPer> void gather(std::vector<T>& data, const std::vector<uint64_t>& order) {
  std::vector<T> out;
  gatherInto<T, kPer>(out, data, order);
  data.swap(out);
}

void assertPermutation([[maybe_unused]] const std::vector<uint64_t>& order, [[maybe_unused]] uint64_t size) {
  assert(order.size() == size);
#ifndef NDEBUG
  std::vector<bool> seen(order.size(), false);
  for (uint64_t i : order) {
    assert(i < order.size() && !seen[i] && "order is not a permutation");
    seen[i] = true;
  }
#endif
}
} // namespace

void applyOrder(PointCloud& cloud, const std::vector<uint64_t>& order) {
  assertPermutation(order, cloud.size());
  // One array at a time, so the peak is one copy of the largest attribute (positions, 12 B/point).
  gather<int32_t, 3>(cloud.positions, order);
  gather<uint32_t, 1>(cloud.colors, order);
  gather<uint16_t, 1>(cloud.intensity, order);
  gather<uint8_t, 1>(cloud.classification, order);
  gather<uint8_t, 1>(cloud.returnNumber, order);
  gather<uint16_t, 1>(cloud.pointSourceId, order);
}

PointCloud orderedCopy(const PointCloud& cloud, const std::vector<uint64_t>& order) {
  assertPermutation(order, cloud.size());
  PointCloud copy;
  copy.scale = cloud.scale;
  copy.offset = cloud.offset;
  copy.bounds = cloud.bounds;
  copy.source = cloud.source;
  gatherInto<int32_t, 3>(copy.positions, cloud.positions, order);
  gatherInto<uint32_t, 1>(copy.colors, cloud.colors, order);
  gatherInto<uint16_t, 1>(copy.intensity, cloud.intensity, order);
  gatherInto<uint8_t, 1>(copy.classification, cloud.classification, order);
  gatherInto<uint8_t, 1>(copy.returnNumber, cloud.returnNumber, order);
  return copy;
}

void reorder(PointCloud& cloud, Order kind, uint64_t seed) {
  if (kind == Order::Original) return;
  std::vector<uint64_t> order;
  computeOrder(order, cloud, kind, seed);
  applyOrder(cloud, order);
}

std::vector<uint32_t> spatialOrder(const ParticleSet& set) {
  const uint64_t n = set.size();
  if (n > 0xFFFFFFFFull) throw UnsupportedError("spatial order: more than 2^32 particles");
  std::vector<uint64_t> order(n);
  sortByKey(order.data(), n, ParticleCellKey(set));
  std::vector<uint32_t> narrow(n);
  parallelBlocks(n, uint64_t(1) << 20, [&](uint64_t, uint64_t begin, uint64_t end) {
    for (uint64_t i = begin; i < end; ++i)
      narrow[i] = static_cast<uint32_t>(order[i]);
  });
  return narrow;
}

} // namespace pointrast
