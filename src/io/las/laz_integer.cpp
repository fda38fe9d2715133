#include "io/las/laz_integer.h"

#include <cassert>

namespace pointrast::io::laz {

IntegerCodec::IntegerCodec(uint32_t bits, uint32_t contexts, uint32_t bitsHigh, uint32_t range)
    : bitsHigh_(bitsHigh) {
  assert(contexts >= 1 && bitsHigh >= 1 && bitsHigh <= 11);
  if (range) {
    // A range that is not a power of two needs the bits of range, a power of two one bit fewer.
    corrBits_ = 0;
    corrRange_ = range;
    for (uint32_t r = range; r; r >>= 1)
      ++corrBits_;
    if (corrRange_ == (1u << (corrBits_ - 1))) --corrBits_;
    corrMin_ = -int32_t(corrRange_ / 2);
  } else if (bits && bits < 32) {
    corrBits_ = bits;
    corrRange_ = 1u << bits;
    corrMin_ = -int32_t(corrRange_ / 2);
  } else {
    corrBits_ = 32;
    corrRange_ = 0;
    corrMin_ = INT32_MIN;
  }
  bitsModels_.resize(contexts);
  for (SymbolModel& m : bitsModels_)
    m.create(corrBits_ + 1);
  correctors_.resize(corrBits_ + 1);
  for (uint32_t i = 1; i <= corrBits_; ++i)
    correctors_[i].create(i <= bitsHigh_ ? 1u << i : 1u << bitsHigh_);
}

void IntegerCodec::reset() {
  k_ = 0;
  for (SymbolModel& m : bitsModels_)
    m.invalidate();
  corrector0_.reset();
  for (uint32_t i = 1; i <= corrBits_; ++i)
    correctors_[i].invalidate();
}

void IntegerCodec::compress(ArithmeticEncoder& enc, int32_t pred, int32_t real, uint32_t context) {
  // Fold the corrector into [corrMin, corrMin + corrRange - 1] (wrapping arithmetic for 32 bits).
  int64_t corr = int64_t(real) - int64_t(pred);
  if (corrRange_) {
    const int64_t corrMax = int64_t(corrMin_) + corrRange_ - 1;
    if (corr < corrMin_)
      corr += corrRange_;
    else if (corr > corrMax)
      corr -= corrRange_;
  } else {
    corr = int32_t(uint32_t(uint64_t(corr)));
  }
  const int64_t c = corr;
  // k: the smallest interval [-(2^k - 1), 2^k] that holds c, the bit width of c1 (counted without a
  // loop, whose exit mispredicted on most values).
  const uint64_t c1 = c <= 0 ? uint64_t(-c) : uint64_t(c - 1);
  const uint32_t k = c1 ? 64 - uint32_t(__builtin_clzll(c1)) : 0;
  SymbolModel& bitsModel = bitsModels_[context];
  bitsModel.ensureReady();
  enc.encodeSymbol(bitsModel, k);
  k_ = k;
  if (k == 0) {
    enc.encodeBit(corrector0_, uint32_t(c));
    return;
  }
  if (k >= 32) return; // only corrMin needs 32 bits, and k alone says so
  uint32_t u = c < 0 ? uint32_t(c + ((int64_t(1) << k) - 1)) : uint32_t(c - 1);
  SymbolModel& model = correctors_[k];
  model.ensureReady();
  if (k <= bitsHigh_) {
    enc.encodeSymbol(model, u);
  } else {
    const uint32_t k1 = k - bitsHigh_;
    enc.encodeSymbol(model, u >> k1);
    enc.writeBits(k1, u & ((1u << k1) - 1));
  }
}

} // namespace pointrast::io::laz
