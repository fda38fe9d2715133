// Vertex orders of the 2021 paper ("Rendering Point Clouds with Compute Shaders and Vertex Order
// Optimization", Schuetz et al.): the order points are stored in decides how often a subgroup's
// points land on one pixel (reduce/dedup) and how well caches and early-z work.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "cloud/cloud.h"

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

// Fills order[0..count) with the permutation that puts the cloud's points into `order`; order[i] is the
// index in the current cloud of the point that goes to position i. Deterministic for a given seed.
void computeOrder(std::vector<uint64_t>& order, const PointCloud& cloud, Order kind, uint64_t seed);

// Reorders every attribute array of the cloud by `order` (as produced above).
void applyOrder(PointCloud& cloud, const std::vector<uint64_t>& order);

// computeOrder + applyOrder (no-op for Original).
void reorder(PointCloud& cloud, Order kind, uint64_t seed);

} // namespace pointrast
