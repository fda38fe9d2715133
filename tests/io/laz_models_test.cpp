// The arithmetic models' reset: a thread's first reset of an alphabet size computes the uniform tables,
// later ones copy them. A copy must leave the model exactly as the computation does, or a LAZ stream
// decodes into wrong points once the model adapts; equal coded bytes over enough symbols to rescale
// the model (more than 2^15) show that every table and counter agrees.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <thread>
#include <vector>

#include "io/las/laz_arithmetic.h"

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

} // namespace

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
