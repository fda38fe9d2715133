// Batches of consecutive points with their bounds, the unit of culling and precision choice of the 2022
// paper ("Software Rasterization of 2 Billion Points in Real Time", Schuetz et al.).
#pragma once

#include <cstdint>
#include <vector>

#include "cloud/cloud.h"

namespace pointrast {

// 128 threads x 80 points = 10240 points per batch (the 2022 paper's choice).
constexpr uint64_t kBatchSize = 10240;

struct Batch {
  uint64_t first = 0; // index of the first point
  uint32_t count = 0; // points in the batch, <= batchSize
  Bounds bounds;      // world bounds of exactly these points
};

// The batch of points [first, first + count) with its bounds. Precondition: the range is in the cloud.
Batch makeBatch(const PointCloud& cloud, uint64_t first, uint32_t count);

// Cuts [0, cloud.size()) into batches of batchSize consecutive points (the last may be shorter).
std::vector<Batch> makeBatches(const PointCloud& cloud, uint64_t batchSize = kBatchSize);

} // namespace pointrast
