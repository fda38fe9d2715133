// The arithmetic models' reset: a thread's first reset of an alphabet size computes the uniform tables,
// later ones copy them. A copy must leave the model exactly as the computation does, or a LAZ stream
// decodes into wrong points once the model adapts; equal coded bytes over enough symbols to rescale
// the model (more than 2^15) show that every table and counter agrees.
//
// The streaming median of coordinate differences: a prediction, so it must give LASzip's value after
// every value added, ties included, or every later point of the chunk decodes wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <thread>
#include <vector>

#include "io/las/laz_arithmetic.h"
#include "io/las/laz_common.h"

using namespace pointrast::io::laz;

namespace {

std::vector<uint8_t> codeSymbols(uint32_t symbols, uint32_t seed) {
  SymbolModel model(symbols);
  model.reset();
  ArithmeticEncoder encoder;
  std::mt19937 random(seed);
  for (int i = 0; i < 40000; ++i) {
    // Mostly a few frequent symbols, so that the counts diverge from uniform and the model rescales.
    const uint32_t range = random() % 4 != 0 ? std::min(3u, symbols) : symbols;
    encoder.encodeSymbol(model, random() % range);
  }
  return encoder.finish();
}

// LASzip's StreamingMedian5 as its specification reads: nested comparisons on each side.
struct ReferenceMedian5 {
  int32_t v[5] = {0, 0, 0, 0, 0};
  bool high = true;
  void add(int32_t n) {
    if (high) {
      if (n < v[2]) {
        v[4] = v[3];
        v[3] = v[2];
        if (n < v[0]) {
          v[2] = v[1];
          v[1] = v[0];
          v[0] = n;
        } else if (n < v[1]) {
          v[2] = v[1];
          v[1] = n;
        } else {
          v[2] = n;
        }
      } else {
        if (n < v[3]) {
          v[4] = v[3];
          v[3] = n;
        } else {
          v[4] = n;
        }
        high = false;
      }
    } else {
      if (v[2] < n) {
        v[0] = v[1];
        v[1] = v[2];
        if (v[4] < n) {
          v[2] = v[3];
          v[3] = v[4];
          v[4] = n;
        } else if (v[3] < n) {
          v[2] = v[3];
          v[3] = n;
        } else {
          v[2] = n;
        }
      } else {
        if (v[1] < n) {
          v[0] = v[1];
          v[1] = n;
        } else {
          v[0] = n;
        }
        high = true;
      }
    }
  }
};

} // namespace

TEST(LazModels, Median5GivesTheReferenceMedianAfterEveryValue) {
  std::mt19937 random(5);
  // Narrow ranges make ties common, wide ones reach the ends of int32.
  for (int32_t range : {3, 20, 1000, INT32_MAX}) {
    Median5 median;
    ReferenceMedian5 reference;
    int differing = 0, moved = 0;
    for (int i = 0; i < 20000; ++i) {
      const int32_t v =
          range == INT32_MAX ? int32_t(random()) : int32_t(random() % uint32_t(2 * range + 1)) - range;
      median.add(v);
      reference.add(v);
      differing += median.get() != reference.v[2];
      moved += median.get() != 0;
    }
    EXPECT_EQ(differing, 0) << "values in +-" << range;
    EXPECT_GT(moved, 10000) << "values in +-" << range; // the median follows the values
  }
}

TEST(LazModels, CopiedResetCodesLikeComputedReset) {
  // A fresh thread: its first reset of each size computes, whatever other tests reset before.
  std::thread([] {
    for (uint32_t symbols : {2u, 3u, 16u, 17u, 100u, 255u, 256u, 257u, 1000u, 2048u}) {
      const std::vector<uint8_t> computed = codeSymbols(symbols, symbols);
      const std::vector<uint8_t> copied = codeSymbols(symbols, symbols);
      EXPECT_GT(computed.size(), 100u) << symbols << " symbols";
      EXPECT_EQ(computed, copied) << symbols << " symbols";
    }
  }).join();
}
