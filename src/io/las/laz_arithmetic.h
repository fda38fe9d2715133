// The adaptive arithmetic coder of LASzip: Amir Said's FastAC ("Fast arithmetic coding implementation:
// 32-bit variables, 32-bit product, periodic updates, table decoding", 2004) as LASzip uses it, with its
// exact constants and model-update schedule, because a LAZ stream decodes correctly only when every model
// adapts exactly as the encoder's did.
//
// The decoder keeps the interval [0, length) and the code value; each symbol narrows the interval by
// the symbol's share of the model's cumulative distribution (15-bit precision for symbol models, 13-bit
// for bit models) and renormalizes by whole bytes when length falls below 2^24.
//
// Hostile input: a decoder never reads outside [begin, end): past the end it reads zero bytes and counts
// them (pastEnd()), which the chunk decoders check against a small slack. Corrupt bytes give wrong
// symbols, never an out-of-range table index or an endless loop (length stays > 0 by construction).
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

// The models' updates loop over every symbol of an alphabet (up to 2048) each time a model is reset or
// rescaled, thousands of times per chunk. In a fuzzing build their coverage counters and comparison
// hooks took most of an execution while saying nothing about the input, so they are left uninstrumented
// there (the sanitizers still check them); other builds are unaffected.
#if defined(__clang__)
#define POINTRAST_LAZ_NO_COVERAGE __attribute__((no_sanitize("coverage")))
#else
#define POINTRAST_LAZ_NO_COVERAGE
#endif

namespace pointrast::io::laz {

inline constexpr uint32_t kMinLength = 0x01000000u; // renormalize below 2^24
inline constexpr uint32_t kMaxLength = 0xFFFFFFFFu;
inline constexpr uint32_t kBitLengthShift = 13; // bit models: probabilities in 1/8192
inline constexpr uint32_t kBitMaxCount = 1u << kBitLengthShift;
inline constexpr uint32_t kLengthShift = 15; // symbol models: distributions in 1/32768
inline constexpr uint32_t kMaxCount = 1u << kLengthShift;

// Probability of a 0 bit, re-estimated every `updateCycle` bits (4, growing by 5/4 up to 64).
struct BitModel {
  uint32_t bit0Prob = 1u << (kBitLengthShift - 1);
  uint32_t bit0Count = 1;
  uint32_t bitCount = 2;
  uint32_t updateCycle = 4;
  uint32_t bitsUntilUpdate = 4;

  void reset() { *this = BitModel{}; }
  POINTRAST_LAZ_NO_COVERAGE void update();
};

// Who uses a model: a decoder's models keep FastAC's decoder table, which every update rebuilds; an
// encoder's never read it, so theirs have none (their distributions, and so their bytes, are the same).
enum class ModelUse : uint8_t { Decode, Encode };

// An adaptive model of `symbols` symbols (2..2048). A decoder's model has a lookup table that maps the
// top bits of value / length to a first guess, refined by bisection (FastAC's table decoding, which
// FastAC keeps for alphabets above 16 symbols; smaller ones bisected the distribution, mispredicting).
class SymbolModel {
public:
  SymbolModel() = default;
  explicit SymbolModel(uint32_t symbols, ModelUse use = ModelUse::Decode) { create(symbols, use); }
  SymbolModel(SymbolModel&&) = default;
  SymbolModel& operator=(SymbolModel&&) = default;

  // Allocates the tables for an alphabet of `symbols` (2..2048) and leaves the model not ready.
  POINTRAST_LAZ_NO_COVERAGE void create(uint32_t symbols, ModelUse use = ModelUse::Decode);
  // Back to the uniform start state (every count 1), as LASzip's initSymbolModel.
  POINTRAST_LAZ_NO_COVERAGE void reset();
  // Marks the model for a reset before its next use: models that a chunk never touches are not reset.
  void invalidate() { ready_ = false; }
  void ensureReady() {
    if (!ready_) reset();
  }
  bool created() const { return symbols_ != 0; }
  uint32_t symbols() const { return symbols_; }

private:
  template <bool> friend class BasicArithmeticDecoder;
  friend class ArithmeticEncoder;
  POINTRAST_LAZ_NO_COVERAGE void update();

  uint32_t* distribution_ = nullptr; // symbols_ entries: cumulative probability, 15-bit scale
  uint32_t* symbolCount_ = nullptr;  // symbols_ entries
  uint32_t* decoderTable_ = nullptr; // tableSize_ + 2 entries and 2 spare words, or null (encoders)
  uint32_t symbols_ = 0, lastSymbol_ = 0, tableSize_ = 0, tableShift_ = 0;
  uint32_t totalCount_ = 0, updateCycle_ = 0, symbolsUntilUpdate_ = 0;
  bool ready_ = false;
  std::unique_ptr<uint32_t[]> storage_;
};

// Where a decoder checks the end of its input. ArithmeticDecoder, which every caller can use, checks
// before the bytes of every symbol. UncheckedDecoder never does: a pointwise chunk decodes with it only
// the points that cannot reach the end of the stream, which it checks once a point (hasRoom), and the
// last points with an ArithmeticDecoder that continues from the same state.
template <bool kCheckEnd> class BasicArithmeticDecoder;
using ArithmeticDecoder = BasicArithmeticDecoder<true>;
using UncheckedDecoder = BasicArithmeticDecoder<false>;

// Bytes a symbol shifts in: clz(length) / 8, and length >= 1 after any symbol (>= 2^5 after raw bits).
inline constexpr size_t kMaxBytesPerSymbol = 3;

template <bool kCheckEnd> class BasicArithmeticDecoder {
public:
  BasicArithmeticDecoder() = default;
  // The same stream at the same state, with the other end check.
  template <bool kOther>
  explicit BasicArithmeticDecoder(const BasicArithmeticDecoder<kOther>& other)
      : ptr_(other.ptr_), end_(other.end_), pastEnd_(other.pastEnd_), value_(other.value_),
        length_(other.length_) {}

  // Starts decoding the bytes [begin, end) (reads the first four as the code value).
  void init(const uint8_t* begin, const uint8_t* end) {
    static_assert(kCheckEnd, "a stream starts with the end checked");
    ptr_ = begin;
    end_ = end;
    pastEnd_ = 0;
    length_ = kMaxLength;
    value_ = uint32_t(nextByte()) << 24;
    value_ |= uint32_t(nextByte()) << 16;
    value_ |= uint32_t(nextByte()) << 8;
    value_ |= uint32_t(nextByte());
  }

  // Whether `symbols` more symbols (raw bits count as one a step) stay inside the input, their
  // four-byte reads included: what an UncheckedDecoder needs before them.
  bool hasRoom(size_t symbols) const {
    return pastEnd_ == 0 && size_t(end_ - ptr_) > kMaxBytesPerSymbol * symbols;
  }

  [[gnu::always_inline]] uint32_t decodeBit(BitModel& m) {
    const uint32_t x = m.bit0Prob * (length_ >> kBitLengthShift);
    uint32_t bit;
    if (value_ < x) {
      bit = 0;
      length_ = x;
      ++m.bit0Count;
    } else {
      bit = 1;
      value_ -= x;
      length_ -= x;
    }
    normalize();
    if (--m.bitsUntilUpdate == 0) m.update();
    return bit;
  }

  // m: a decoder's model (ModelUse::Decode), which always has its decoder table.
  [[gnu::always_inline]] uint32_t decodeSymbol(SymbolModel& m) {
    const uint32_t* distribution = m.distribution_;
    const uint32_t l = length_ >> kLengthShift;
    const uint32_t dv = value_ / l;
    // value < length holds for every stream an encoder wrote, which keeps t <= tableSize; corrupt
    // bytes can break it, so the index is clamped rather than trusted.
    uint32_t t = dv >> m.tableShift_;
    if (t > m.tableSize_) t = m.tableSize_;
    uint32_t sym = m.decoderTable_[t];
    uint32_t n = m.decoderTable_[t + 1] + 1;
    while (n > sym + 1) {
      const uint32_t k = (sym + n) >> 1;
      if (distribution[k] > dv)
        n = k;
      else
        sym = k;
    }
    const uint32_t x = distribution[sym] * l;
    // The last symbol's interval ends at length itself. Its entry sym + 1 is the first count (the
    // model's storage continues), read and dropped by a conditional move: a branch on it
    // mispredicts. The empty asm keeps GCC from moving the product into a branch (encodeSymbol).
    uint32_t next = distribution[sym + 1] * l;
    asm("" : "+r"(next));
    const uint32_t y = sym == m.lastSymbol_ ? length_ : next;
    value_ -= x;
    length_ = y - x;
    normalize();
    ++m.symbolCount_[sym];
    if (--m.symbolsUntilUpdate_ == 0) m.update();
    return sym;
  }

  // Raw bits, equiprobable (LASzip readBits: at most 32, values above 19 bits in two steps). Not
  // recursive, so that it inlines: GCC compiled the recursive form out of line, and the coder whose
  // address that call took lived on the stack, its state stored and loaded around every symbol.
  [[gnu::always_inline]] uint32_t readBits(uint32_t bits) {
    if (bits > 19) {
      const uint32_t low = readShort();
      return (readFewBits(bits - 16) << 16) | low;
    }
    return readFewBits(bits);
  }
  [[gnu::always_inline]] uint32_t readShort() { return readFewBits(16) & 0xFFFF; }
  [[gnu::always_inline]] uint32_t readInt() {
    const uint32_t low = readShort();
    return (readShort() << 16) | low;
  }
  uint64_t readInt64() {
    const uint64_t low = readInt();
    return (uint64_t(readInt()) << 32) | low;
  }

  // Bytes read past the end of the input (as zeros).
  size_t pastEnd() const { return pastEnd_; }
  const uint8_t* position() const { return ptr_; }

private:
  template <bool> friend class BasicArithmeticDecoder;

  // 1 to 19 raw bits.
  [[gnu::always_inline]] uint32_t readFewBits(uint32_t bits) {
    const uint32_t sym = value_ / (length_ >>= bits);
    value_ -= length_ * sym;
    normalize();
    return sym;
  }

  [[gnu::always_inline]] uint8_t nextByte() {
    if (ptr_ < end_) return *ptr_++;
    ++pastEnd_;
    return 0;
  }
  // After every symbol: shift in the bytes that bring length back to 2^24 or more (clz(length) / 8 of
  // them, 0 to 3) without a branch on length, which mispredicts about every third symbol; near the end
  // of the input, byte by byte.
  [[gnu::always_inline]] void normalize() {
    if (!kCheckEnd || end_ - ptr_ >= 4) [[likely]] {
      const uint32_t shift = uint32_t(__builtin_clz(length_ | 1)) & 24; // 8 bits a byte shifted in
      uint32_t next;
      std::memcpy(&next, ptr_, 4);
      next = __builtin_bswap32(next);
#if defined(__x86_64__)
      // value << shift with the top `shift` bits of next, a shift of 0 included, in one instruction;
      // GCC compiles the portable form below into five.
      asm("shldl %%cl, %1, %0" : "+r"(value_) : "r"(next), "c"(shift) : "cc");
#else
      value_ = uint32_t(((uint64_t(value_) << 32 | next) << shift) >> 32);
#endif
      length_ <<= shift;
      ptr_ += shift >> 3;
    } else if (length_ < kMinLength) {
      renormalize();
    }
  }
  [[gnu::always_inline]] void renormalize() {
    do {
      value_ = (value_ << 8) | nextByte();
    } while ((length_ <<= 8) < kMinLength);
  }

  const uint8_t* ptr_ = nullptr;
  const uint8_t* end_ = nullptr;
  size_t pastEnd_ = 0;
  uint32_t value_ = 0, length_ = kMaxLength;
};

// The matching encoder: LAZ chunks (the LAS/LAZ and COPC writers) and chunk tables.
//
// Its bytes go into a buffer it keeps from chunk to chunk. After a symbol it shifts out the bytes that
// bring length back to 2^24 or more (clz(length) / 8 of them, 0 to 3) without a branch on length,
// which mispredicts about every third symbol: the top four bytes of base are stored and the pointer
// advances by that count (the same bytes FastAC's loop writes one at a time).
//
// A symbol works on local copies of base and length and updates its model before it stores bytes:
// a byte store may alias anything, so state read after it would be loaded again, and the state stored
// as separate words and read back as one (GCC paired base and length in a vector register) stalled
// store forwarding on every symbol.
class ArithmeticEncoder {
public:
  ArithmeticEncoder() = default;
  ArithmeticEncoder(ArithmeticEncoder&&) = default;
  ArithmeticEncoder& operator=(ArithmeticEncoder&&) = default;

  [[gnu::always_inline]] void encodeBit(BitModel& m, uint32_t bit) {
    const uint32_t x = m.bit0Prob * (length_ >> kBitLengthShift);
    const uint32_t add = bit ? x : 0;
    const uint32_t base = base_ + add;
    const uint32_t length = bit ? length_ - x : x;
    m.bit0Count += bit == 0;
    if (--m.bitsUntilUpdate == 0) m.update();
    if (base < add) [[unlikely]]
      propagateCarry();
    normalize(base, length);
  }

  [[gnu::always_inline]] void encodeSymbol(SymbolModel& m, uint32_t sym) {
    assert(sym < m.symbols_);
    const uint32_t* distribution = m.distribution_;
    const uint32_t l = length_ >> kLengthShift;
    const uint32_t x = distribution[sym] * l;
    // The last symbol's interval ends at length itself. Its entry sym + 1 is the first count (the
    // model's storage continues), read and dropped by a conditional move: the last symbol of a
    // corrector's model is as frequent as any other, and a branch on it mispredicted. GCC made a branch
    // of the ?: by moving the product into one arm; the empty asm, which takes the product, keeps it.
    uint32_t next = distribution[sym + 1] * l;
    asm("" : "+r"(next));
    const uint32_t length = (sym == m.lastSymbol_ ? length_ : next) - x;
    const uint32_t base = base_ + x;
    ++m.symbolCount_[sym];
    if (--m.symbolsUntilUpdate_ == 0) m.update();
    if (base < x) [[unlikely]]
      propagateCarry();
    normalize(base, length);
  }

  void writeBits(uint32_t bits, uint32_t value);
  // Flushes the interval (with the trailing zero bytes FastAC writes so a decoder never reads past the
  // end) and returns the bytes, valid until this encoder is used again; it then starts a new stream.
  std::span<const uint8_t> flush();
  // flush() into a vector of its own.
  std::vector<uint8_t> finish();

private:
  // Stores the interval (base, length) after shifting out its settled bytes.
  [[gnu::always_inline]] void normalize(uint32_t base, uint32_t length) {
    uint8_t* p = ptr_;
    if (p >= limit_) [[unlikely]]
      p = grow();
    const uint32_t n = uint32_t(__builtin_clz(length | 1)) >> 3;
    const uint32_t bytes = __builtin_bswap32(base);
    std::memcpy(p, &bytes, 4);
    ptr_ = p + n;
    base_ = base << (8 * n);
    length_ = length << (8 * n);
  }
  uint8_t* grow(); // returns the new ptr_
  void propagateCarry();
  std::unique_ptr<uint8_t[]> buffer_;
  uint8_t* ptr_ = nullptr;   // the next byte in buffer_
  uint8_t* limit_ = nullptr; // buffer_'s end - 3: a four-byte store fits at ptr_ while ptr_ < limit_
  uint32_t base_ = 0, length_ = kMaxLength;
};

} // namespace pointrast::io::laz
