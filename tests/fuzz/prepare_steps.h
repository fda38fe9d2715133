// What a render does to a cloud on the host before the upload (src/cloud): display colors, the vertex
// orders, float positions relative to the origin and the batched layout. Shared by the prepare fuzz
// target and the replay of its regression inputs (tests/io/fuzz_regressions_test.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "cloud/batch_words.h"
#include "cloud/cloud.h"
#include "cloud/order.h"

namespace fuzz {

inline void prepareLikeRender(const pointrast::PointCloud& cloud) {
  const uint64_t n = cloud.size();
  std::vector<uint32_t> colors(n);
  pointrast::displayColors(colors.data(), cloud, 0, n);
  std::vector<float> relative(3 * n);
  pointrast::toRelativeFloat(relative.data(), cloud, 0, n, cloud.origin());
  std::vector<uint64_t> order;
  for (pointrast::Order kind : {pointrast::Order::Morton, pointrast::Order::ShuffledMorton}) {
    pointrast::computeOrder(order, cloud, kind, 1);
    if (order.size() != n) __builtin_trap();
  }
  // Small batches: many of them, each with its own bounds, from a small input.
  for (const pointrast::Batch& batch : pointrast::makeBatches(cloud, 64)) {
    std::vector<uint32_t> high(batch.count), medium(batch.count), low(batch.count);
    pointrast::encodeBatchWords(high.data(), medium.data(), low.data(), cloud, batch);
  }
}

} // namespace fuzz
