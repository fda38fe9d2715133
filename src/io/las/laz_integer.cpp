#include "io/las/laz_integer.h"

#include <cassert>

namespace pointrast::io::laz {

IntegerCodec::IntegerCodec(uint32_t bits, uint32_t contexts, uint32_t bitsHigh, uint32_t range, ModelUse use)
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
  // The fold of a corrector: over the range, or over 2^32 (the wrapping difference) for 32 bits.
  foldRange_ = corrRange_ ? int64_t(corrRange_) : int64_t(1) << 32;
  corrMax_ = corrMin_ + foldRange_ - 1;
  bitsModels_.resize(contexts);
  for (SymbolModel& m : bitsModels_)
    m.create(corrBits_ + 1, use);
  correctors_.resize(corrBits_ + 1);
  for (uint32_t i = 1; i <= corrBits_; ++i)
    correctors_[i].create(i <= bitsHigh_ ? 1u << i : 1u << bitsHigh_, use);
}

void IntegerCodec::reset() {
  k_ = 0;
  for (SymbolModel& m : bitsModels_)
    m.invalidate();
  corrector0_.reset();
  for (uint32_t i = 1; i <= corrBits_; ++i)
    correctors_[i].invalidate();
}

} // namespace pointrast::io::laz
