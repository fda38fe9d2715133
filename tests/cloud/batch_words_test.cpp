// The 2022 three-word coordinate layout: bit layout, and decoding error within the stated bound for one,
// two and three words, on generated terrain (UTM-size coordinates) and on degenerate batches.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "cloud/batch_words.h"
#include "cloud/generate.h"

namespace pointrast {
namespace {

TEST(BatchWords, BitLayoutPutsTenBitsPerAxisPerWord) {
  // One point at the max corner of its batch and one at the min corner.
  PointCloud cloud;
  cloud.scale = glm::dvec3(1e-3);
  cloud.positions = {0, 0, 0, 1000, 2000, 3000};
  computeBounds(cloud);
  std::vector<Batch> batches = makeBatches(cloud);
  ASSERT_EQ(batches.size(), 1u);
  uint32_t h[2], m[2], l[2];
  encodeBatchWords(h, m, l, cloud, batches[0]);
  EXPECT_EQ(h[0], 0u);
  EXPECT_EQ(m[0], 0u);
  EXPECT_EQ(l[0], 0u);
  // 2^30 - 1 on every axis: all 30 bits set, so every word holds 1023 | 1023 << 10 | 1023 << 20.
  EXPECT_EQ(h[1], 0x3FFFFFFFu);
  EXPECT_EQ(m[1], 0x3FFFFFFFu);
  EXPECT_EQ(l[1], 0x3FFFFFFFu);
}

// The encoder rounds each axis inline; it must give exactly what std::llround and a clamp to [0, 2^30 - 1]
// give, for every point of real-size batches (fractions of one half included: small integer extents
// make (q - min) / size * (2^30 - 1) land on halves).
TEST(BatchWords, InlineRoundingEqualsLlroundAndClamp) {
  auto reference = [](double value, double min, double size) -> uint32_t {
    if (!(size > 0)) return 0;
    const double t = (value - min) / size * double(kBatchCoordinateMax);
    return uint32_t(std::clamp(std::llround(t), 0ll, (long long)kBatchCoordinateMax));
  };
  GenerateOptions options;
  options.points = 40'000;
  options.progress = false;
  PointCloud terrain = generateScene(Scene::Terrain, options);
  // Extent 2 on each axis: positions 0, 1, 2 put t on 0, (2^30 - 1) / 2, 2^30 - 1. 303 points: the encoder
  // takes four points at a time, and the last three on their own.
  PointCloud halves;
  halves.scale = glm::dvec3(1.0);
  for (int32_t i = 0; i < 303; ++i)
    halves.positions.insert(halves.positions.end(), {i % 3, (i / 3) % 3, (i / 9) % 3});
  computeBounds(halves);
  uint64_t checked = 0;
  for (const PointCloud* cloud : {&terrain, &halves})
    for (const Batch& batch : makeBatches(*cloud)) {
      std::vector<uint32_t> h(batch.count), m(batch.count), l(batch.count);
      encodeBatchWords(h.data(), m.data(), l.data(), *cloud, batch);
      const glm::dvec3 min = batch.bounds.min, size = batch.bounds.size();
      for (uint32_t k = 0; k < batch.count; ++k) {
        const glm::dvec3 p = cloud->world(batch.first + k);
        for (int a = 0; a < 3; ++a) {
          const uint32_t q = reference(p[a], min[a], size[a]);
          const uint32_t got = (h[k] >> (10 * a) & 1023u) << 20 | (m[k] >> (10 * a) & 1023u) << 10 |
                               (l[k] >> (10 * a) & 1023u);
          ASSERT_EQ(got, q) << "point " << batch.first + k << " axis " << a;
          ++checked;
        }
      }
    }
  EXPECT_EQ(checked, 3u * (terrain.size() + halves.size()));
}

TEST(BatchWords, DecodingErrorStaysWithinTheBoundForEachPrecision) {
  GenerateOptions options;
  options.points = 50'000;
  options.progress = false;
  PointCloud cloud = generateScene(Scene::Terrain, options);
  std::vector<Batch> batches = makeBatches(cloud);
  for (const Batch& batch : batches) {
    std::vector<uint32_t> h(batch.count), m(batch.count), l(batch.count);
    encodeBatchWords(h.data(), m.data(), l.data(), cloud, batch);
    for (int words = 1; words <= 3; ++words) {
      glm::dvec3 bound = batchWordsError(batch, words);
      for (uint32_t k = 0; k < batch.count; ++k) {
        glm::dvec3 error =
            glm::abs(decodeBatchWords(batch, h[k], m[k], l[k], words) - cloud.world(batch.first + k));
        ASSERT_LE(error.x, bound.x) << "batch at " << batch.first << ", point " << k << ", " << words
                                    << " words";
        ASSERT_LE(error.y, bound.y);
        ASSERT_LE(error.z, bound.z);
      }
    }
    // The full 30 bits resolve the 1 mm input grid exactly enough: below a micrometre for batches
    // of a few hundred metres.
    EXPECT_LT(batchWordsError(batch, 3).x, 1e-6 * std::max(1.0, batch.bounds.size().x / 100.0));
  }
}

TEST(BatchWords, FlatAxesEncodeAsZeroAndDecodeExactly) {
  PointCloud cloud;
  cloud.scale = glm::dvec3(1e-3);
  cloud.offset = glm::dvec3(500000, 4000000, 100);
  for (int i = 0; i < 300; ++i)
    cloud.positions.insert(cloud.positions.end(), {i, 7, 0}); // y and z flat
  computeBounds(cloud);
  std::vector<Batch> batches = makeBatches(cloud, 128);
  ASSERT_EQ(batches.size(), 3u);
  EXPECT_EQ(batches[2].count, 44u);
  for (const Batch& batch : batches) {
    std::vector<uint32_t> h(batch.count), m(batch.count), l(batch.count);
    encodeBatchWords(h.data(), m.data(), l.data(), cloud, batch);
    for (uint32_t k = 0; k < batch.count; ++k) {
      EXPECT_EQ(h[k] >> 10, 0u) << "y and z words must be 0 on flat axes";
      glm::dvec3 p = decodeBatchWords(batch, h[k], m[k], l[k], 3);
      glm::dvec3 expected = cloud.world(batch.first + k);
      EXPECT_DOUBLE_EQ(p.y, expected.y);
      EXPECT_DOUBLE_EQ(p.z, expected.z);
      EXPECT_NEAR(p.x, expected.x, batchWordsError(batch, 3).x);
    }
  }
}

} // namespace
} // namespace pointrast
