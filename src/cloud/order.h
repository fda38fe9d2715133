// Vertex orders of the 2021 paper ("Rendering Point Clouds with Compute Shaders and Vertex Order
// Optimization", Schuetz et al.): the order points are stored in decides how often a subgroup's
// points land on one pixel (reduce/dedup) and how well caches and early-z work.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "cloud/cloud.h"
#include "cloud/particles.h"

namespace pointrast {

enum class Order {
  Original,       // as read or generated
  Morton,         // Morton (Z-order) code, 21 bits per axis over the cubic bounds
  Shuffled,       // uniformly random permutation
  ShuffledMorton, // Morton order, then runs of kShuffleRun points moved as a whole, order inside kept
};

// Points per run in ShuffledMorton: a run stays together so a workgroup still sees a local patch.
constexpr uint64_t kShuffleRun = 128;

// Parses "original", "morton", "shuffled", "shuffled-morton"; throws InputError naming the choices.
Order parseOrder(std::string_view name);
const char* orderName(Order order);

// 63-bit Morton code of a point given as 21-bit integer cell coordinates:
// bit 3k = x bit k, bit 3k+1 = y bit k, bit 3k+2 = z bit k.
uint64_t mortonCode(uint32_t x, uint32_t y, uint32_t z);
// The inverse: the 21-bit coordinates of a 63-bit Morton code (bit 63 ignored).
void mortonDecode(uint64_t code, uint32_t& x, uint32_t& y, uint32_t& z);

// Fills order[0..count) with the permutation that puts the cloud's points into `order`; order[i] is the
// index in the current cloud of the point that goes to position i. Deterministic for a given seed, and
// the same whatever the number of threads: points with equal keys (Morton codes) keep their relative
// order. The Morton cube is taken from the points themselves, not from cloud.bounds. Uses all hardware
// threads; memory beyond `order` itself is 2 B/point while it runs plus a few MB per thread
// (ShuffledMorton: one more copy of the order, 8 B/point).
void computeOrder(std::vector<uint64_t>& order, const PointCloud& cloud, Order kind, uint64_t seed);

// Reorders every non-empty attribute array of the cloud by `order` (as produced above; it must be a
// permutation of [0, cloud.size())). Parallel; one array at a time, so the peak is one extra copy of
// the positions (12 B/point). Bounds are unchanged.
void applyOrder(PointCloud& cloud, const std::vector<uint64_t>& order);

// A copy of the cloud with every non-empty attribute array in `order` (a permutation as above), the source
// left as it is: for a caller that keeps the original, such as a benchmark measuring several orders.
PointCloud orderedCopy(const PointCloud& cloud, const std::vector<uint64_t>& order);

// computeOrder + applyOrder (no-op for Original).
void reorder(PointCloud& cloud, Order kind, uint64_t seed);

// The particles of the set (indices) in the Morton order of the cells of a 1024^3 grid over their centers'
// bounds (set.bounds, each axis cut in 1024), in the set's order within a cell: consecutive particles lie
// close together, as sphere-compute's batches need. The sort of computeOrder, on all hardware threads;
// throws UnsupportedError past 2^32 particles.
std::vector<uint32_t> spatialOrder(const ParticleSet& set);

} // namespace pointrast
