#include "cloud/batch.h"

#include <cassert>
#include <limits>

#include "base/parallel.h"
#include "cloud/detail.h"

namespace pointrast {

Batch makeBatch(const PointCloud& cloud, uint64_t first, uint32_t count) {
  assert(first + count <= cloud.size());
  Batch batch;
  batch.first = first;
  batch.count = count;
  batch.bounds =
      detail::worldBounds(detail::quantBox(cloud.positions.data(), first, count), cloud.scale, cloud.offset);
  return batch;
}

std::vector<Batch> makeBatches(const PointCloud& cloud, uint64_t batchSize) {
  assert(batchSize > 0 && batchSize <= std::numeric_limits<uint32_t>::max());
  const uint64_t n = cloud.size();
  std::vector<Batch> batches((n + batchSize - 1) / batchSize);
  // 64 batches (655 k points at the default size) per job keeps the per-job overhead negligible.
  parallelBlocks(batches.size(), 64, [&](uint64_t, uint64_t begin, uint64_t end) {
    for (uint64_t b = begin; b < end; ++b) {
      const uint64_t first = b * batchSize;
      batches[b] = makeBatch(cloud, first, static_cast<uint32_t>(std::min(batchSize, n - first)));
    }
  });
  return batches;
}

} // namespace pointrast
