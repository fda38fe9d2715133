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
  IntegerCodec(uint32_t bits, uint32_t contexts, uint32_t bitsHigh = 8, uint32_t range = 0,
               ModelUse use = ModelUse::Decode);
  // An encoder's codec (its models without decoder tables).
  IntegerCodec(uint32_t bits, uint32_t contexts, ModelUse use) : IntegerCodec(bits, contexts, 8, 0, use) {}
  IntegerCodec(IntegerCodec&&) = default;
  IntegerCodec& operator=(IntegerCodec&&) = default;

  // Start of a chunk: every model back to its start state (lazily, at first use).
  void reset();

  // Decoder: ArithmeticDecoder or UncheckedDecoder.
  template <class Decoder>
  [[gnu::always_inline]] int32_t decompress(Decoder& dec, int32_t pred, uint32_t context = 0) {
    uint32_t real = uint32_t(pred) + uint32_t(readCorrector(dec, context));
    if (int32_t(real) < 0)
      real += corrRange_;
    else if (real >= corrRange_)
      real -= corrRange_;
    return int32_t(real);
  }
  [[gnu::always_inline]] void compress(ArithmeticEncoder& enc, int32_t pred, int32_t real,
                                       uint32_t context = 0) {
    // The corrector folded into [corrMin, corrMax]; for 32-bit values that is the wrapping difference.
    // Everything up to the symbols is without branches: the size and the sign of a corrector are noise,
    // and branches on them mispredict.
    const int64_t d = int64_t(real) - int64_t(pred);
    const int64_t c = d + (foldRange_ & -int64_t(d < corrMin_)) - (foldRange_ & -int64_t(d > corrMax_));
    // k: the smallest interval [-(2^k - 1), 2^k] that holds c, the bit width of c1 (0 for c1 = 0).
    const uint64_t c1 = c <= 0 ? uint64_t(-c) : uint64_t(c - 1);
    const uint32_t k = 63 - uint32_t(__builtin_clzll(2 * c1 + 1));
    SymbolModel& bitsModel = bitsModels_[context];
    bitsModel.ensureReady();
    enc.encodeSymbol(bitsModel, k);
    k_ = k;
    if (k == 0) {
      enc.encodeBit(corrector0_, uint32_t(c));
      return;
    }
    if (k >= 32) return; // only corrMin needs 32 bits, and k alone says so
    // c in [-(2^k - 1), -2^(k-1)] as [0, 2^(k-1)), c in [2^(k-1) + 1, 2^k] as [2^(k-1), 2^k).
    const uint32_t u = uint32_t(c) - 1 + (uint32_t(c < 0) << k);
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

  uint32_t getK() const { return k_; }

private:
  template <class Decoder> [[gnu::always_inline]] int32_t readCorrector(Decoder& dec, uint32_t context) {
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
    // c in [0, 2^(k-1)) stands for [-(2^k - 1), -2^(k-1)], c in [2^(k-1), 2^k) for [2^(k-1) + 1, 2^k]:
    // c + 1, less 2^k for the lower half. Without a branch: the sign of a corrector is noise, and the
    // branch on it mispredicted 1.4 times a point of format 3 (cachegrind).
    c += 1 - (uint32_t(c < (1u << (k_ - 1))) << k_);
    return int32_t(c);
  }

  uint32_t bitsHigh_ = 8;
  uint32_t corrBits_ = 32;
  uint32_t corrRange_ = 0;
  int32_t corrMin_ = INT32_MIN;
  int64_t corrMax_ = INT32_MAX, foldRange_ = int64_t(1) << 32; // compress()'s fold
  uint32_t k_ = 0;
  std::vector<SymbolModel> bitsModels_; // one per context, corrBits + 1 symbols
  BitModel corrector0_;
  std::vector<SymbolModel> correctors_; // [1..corrBits]: 2^k symbols up to 2^bitsHigh
};

} // namespace pointrast::io::laz
