#include "cloud/batch.h"

#include <gtest/gtest.h>

#include "test_clouds.h"

namespace pointrast {
namespace {

void expectTiling(const PointCloud& cloud, uint64_t batchSize) {
  std::vector<Batch> batches = makeBatches(cloud, batchSize);
  EXPECT_EQ(batches.size(), (cloud.size() + batchSize - 1) / batchSize);
  uint64_t next = 0;
  for (const Batch& b : batches) {
    ASSERT_EQ(b.first, next); // consecutive, no gap, no overlap: every point exactly once
    ASSERT_GT(b.count, 0u);
    ASSERT_LE(b.count, batchSize);
    if (&b != &batches.back()) {
      ASSERT_EQ(b.count, batchSize);
    }
    Bounds tight;
    for (uint64_t i = b.first; i < b.first + b.count; ++i)
      tight.expand(cloud.world(i));
    ASSERT_EQ(b.bounds.min, tight.min); // exact, not merely containing
    ASSERT_EQ(b.bounds.max, tight.max);
    next += b.count;
  }
  EXPECT_EQ(next, cloud.size());
}

TEST(MakeBatches, CoverEveryPointOnceWithTightBounds) {
  PointCloud cloud = testing::randomCloud(10 * kBatchSize + 123, 1'000'000, {500000.0, 4000000.0, 20.0});
  expectTiling(cloud, kBatchSize);
  expectTiling(cloud, 1000);
  expectTiling(cloud, 1);
}

TEST(MakeBatches, ExactMultipleAndSmallClouds) {
  expectTiling(testing::randomCloud(3 * 500), 500);
  expectTiling(testing::randomCloud(7), kBatchSize);
  EXPECT_TRUE(makeBatches(PointCloud{}).empty());
}

TEST(MakeBatches, NegativeScale) {
  PointCloud cloud = testing::randomCloud(5000);
  cloud.scale = {-0.5, 0.25, -1.0};
  computeBounds(cloud);
  expectTiling(cloud, 999);
}

} // namespace
} // namespace pointrast
