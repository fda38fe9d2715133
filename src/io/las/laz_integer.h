// LASzip's integer compressor: a value is coded as the corrector c = real - prediction, folded into the
// range of `bits`-bit integers. First k, the number of bits c needs (one symbol of corrBits + 1, with a
// model per caller context), then c itself: for k = 0 one bit (c is 0 or 1), for k <= bitsHigh one
// symbol of 2^k, above that the top bitsHigh bits as a symbol and the low k - bitsHigh bits raw.
// getK() of the last value is itself a context for the next coordinate (LASzip's k_bits).
#pragma once

#include <cstdint>
#include <vector>

#include "io/las/laz_arithmetic.h"

namespace pointrast::io::laz {

class IntegerCodec {
public:
  IntegerCodec() = default;
  // bits: width of the values (32 for coordinates, 16 for intensity); contexts: caller contexts.
  IntegerCodec(uint32_t bits, uint32_t contexts, uint32_t bitsHigh = 8, uint32_t range = 0);
  IntegerCodec(IntegerCodec&&) = default;
  IntegerCodec& operator=(IntegerCodec&&) = default;

  // Start of a chunk: every model back to its start state (lazily, at first use).
  void reset();

  [[gnu::always_inline]] int32_t decompress(ArithmeticDecoder& dec, int32_t pred, uint32_t context = 0) {
    uint32_t real = uint32_t(pred) + uint32_t(readCorrector(dec, context));
    if (int32_t(real) < 0)
      real += corrRange_;
    else if (real >= corrRange_)
      real -= corrRange_;
    return int32_t(real);
  }
  void compress(ArithmeticEncoder& enc, int32_t pred, int32_t real, uint32_t context = 0);

  uint32_t getK() const { return k_; }

private:
  [[gnu::always_inline]] int32_t readCorrector(ArithmeticDecoder& dec, uint32_t context) {
    SymbolModel& bitsModel = bitsModels_[context];
    bitsModel.ensureReady();
    k_ = dec.decodeSymbol(bitsModel);
    if (k_ == 0) return int32_t(dec.decodeBit(corrector0_));
    if (k_ >= 32) return corrMin_;
    SymbolModel& model = correctors_[k_];
    model.ensureReady();
    uint32_t c;
    if (k_ <= bitsHigh_) {
      c = dec.decodeSymbol(model);
    } else {
      const uint32_t k1 = k_ - bitsHigh_;
      c = dec.decodeSymbol(model);
      c = (c << k1) | dec.readBits(k1);
    }
    // c in [0, 2^(k-1)) stands for [-(2^k - 1), -2^(k-1)], c in [2^(k-1), 2^k) for [2^(k-1) + 1, 2^k].
    if (c >= (1u << (k_ - 1)))
      c += 1;
    else
      c -= (1u << k_) - 1;
    return int32_t(c);
  }

  uint32_t bitsHigh_ = 8;
  uint32_t corrBits_ = 32;
  uint32_t corrRange_ = 0;
  int32_t corrMin_ = INT32_MIN;
  uint32_t k_ = 0;
  std::vector<SymbolModel> bitsModels_; // one per context, corrBits + 1 symbols
  BitModel corrector0_;
  std::vector<SymbolModel> correctors_; // [1..corrBits]: 2^k symbols up to 2^bitsHigh
};

} // namespace pointrast::io::laz
