// LASzip's pointwise item decoders, version 2 (LAS point formats 0-5): every point is coded item after
// item in one arithmetic-coded stream per chunk, each item predicting from the same item of the previous
// point. The first point of a chunk is stored raw and seeds every item's "last" state.
//
// Each decoder writes its item's raw LAS bytes (little endian, as in an uncompressed record).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "io/las/laz_arithmetic.h"
#include "io/las/laz_common.h"
#include "io/las/laz_format.h"
#include "io/las/laz_integer.h"

namespace pointrast::io::laz {

// A model per possible previous byte value, created on first use (most files use a handful).
class ContextModels {
public:
  ContextModels(size_t contexts, uint32_t symbols, ModelUse use = ModelUse::Decode)
      : models_(contexts), symbols_(symbols), use_(use) {}
  SymbolModel& operator[](size_t context) {
    SymbolModel& m = models_[context];
    if (!m.created()) m.create(symbols_, use_);
    m.ensureReady();
    return m;
  }
  void invalidate() {
    for (SymbolModel& m : models_)
      if (m.created()) m.invalidate();
  }

private:
  std::vector<SymbolModel> models_;
  uint32_t symbols_;
  ModelUse use_;
};

// X, Y, Z, intensity, return bits, classification, scan angle rank, user data, point source id (20 B).
class Point10Decoder {
public:
  // Coded steps a point can take (UncheckedDecoder's bound): the changed-values and return symbols,
  // intensity and point source id (4 each: k, a corrector symbol, up to two raw-bit steps),
  // classification, scan angle and user data (1 each), X, Y, Z (4 each).
  static constexpr size_t kMaxSymbols = 2 + 4 + 4 + 3 + 3 * 4;
  Point10Decoder();
  void init(const uint8_t* item);
  template <class Decoder> void read(Decoder& dec, uint8_t* item);

private:
  SymbolModel changedValues_{64};
  IntegerCodec intensity_{16, 4};
  SymbolModel scanAngleRank_[2] = {SymbolModel(256), SymbolModel(256)};
  IntegerCodec pointSourceId_{16, 1};
  ContextModels bitByte_{256, 256}, classification_{256, 256}, userData_{256, 256};
  IntegerCodec dx_{32, 2}, dy_{32, 22}, z_{32, 20};

  uint8_t last_[20] = {};
  uint16_t lastIntensity_[16] = {};
  Median5 lastXDiff_[16], lastYDiff_[16];
  int32_t lastHeight_[8] = {};
};

// GPS times (the bits of a double) in four sequences, so interleaved flight lines each keep their own
// prediction: a time is a multiple of its sequence's last integer difference plus a corrector, or a
// full 64-bit value that starts a new sequence. Shared by GPSTIME11 v2 and POINT14 v3, which number
// their symbols differently.
struct GpsSequences {
  uint32_t last = 0, next = 0;
  uint64_t time[4] = {};
  int32_t diff[4] = {};
  int32_t extremeCounter[4] = {};

  void reset(uint64_t firstTime) { *this = GpsSequences{0, 0, {firstTime, 0, 0, 0}, {}, {}}; }
  uint64_t current() const { return time[last]; }
  // After a zero difference: a new 32-bit difference.
  template <class Decoder> void readFirstDiff(Decoder& dec, IntegerCodec& ic);
  // A full time: the high word predicted by the current time's, the low word raw; starts a sequence.
  template <class Decoder> void readFull(Decoder& dec, IntegerCodec& ic);
  // Multiplier symbol 0..510 (never 1, which callers handle as "the last difference again").
  template <class Decoder> void readMultiple(Decoder& dec, IntegerCodec& ic, uint32_t multi);
  template <class Decoder> void readSameDiff(Decoder& dec, IntegerCodec& ic);
};

// Multiplier symbols shared by both generations: 1..499 that multiple of the last difference, 500 a
// large multiple, 501..510 the multiples -1..-10, 0 a difference unrelated to the last one. A
// multiplier at an extreme (0, 500, -10) four times in a row replaces the sequence's difference.
inline constexpr uint32_t kGpsMulti = 500;
inline constexpr int32_t kGpsMultiMinus = -10;

template <class Decoder>
[[gnu::always_inline]] inline void GpsSequences::readFirstDiff(Decoder& dec, IntegerCodec& ic) {
  diff[last] = ic.decompress(dec, 0, 0);
  time[last] += uint64_t(int64_t(diff[last]));
  extremeCounter[last] = 0;
}

template <class Decoder>
[[gnu::always_inline]] inline void GpsSequences::readFull(Decoder& dec, IntegerCodec& ic) {
  next = (next + 1) & 3;
  const uint32_t high = uint32_t(ic.decompress(dec, int32_t(uint32_t(time[last] >> 32)), 8));
  time[next] = (uint64_t(high) << 32) | dec.readInt();
  last = next;
  diff[last] = 0;
  extremeCounter[last] = 0;
}

template <class Decoder>
[[gnu::always_inline]] inline void GpsSequences::readSameDiff(Decoder& dec, IntegerCodec& ic) {
  time[last] += uint64_t(int64_t(ic.decompress(dec, diff[last], 1)));
  extremeCounter[last] = 0;
}

template <class Decoder>
[[gnu::always_inline]] inline void GpsSequences::readMultiple(Decoder& dec, IntegerCodec& ic,
                                                              uint32_t multi) {
  auto countExtreme = [&](int32_t d) {
    if (++extremeCounter[last] > 3) {
      diff[last] = d;
      extremeCounter[last] = 0;
    }
  };
  int32_t d;
  if (multi == 0) {
    d = ic.decompress(dec, 0, 7);
    countExtreme(d);
  } else if (multi < kGpsMulti) {
    d = ic.decompress(dec, mulWrap(int32_t(multi), diff[last]), multi < 10 ? 2 : 3);
  } else if (multi == kGpsMulti) {
    d = ic.decompress(dec, mulWrap(int32_t(kGpsMulti), diff[last]), 4);
    countExtreme(d);
  } else {
    const int32_t negative = int32_t(kGpsMulti) - int32_t(multi);
    if (negative > kGpsMultiMinus) {
      d = ic.decompress(dec, mulWrap(negative, diff[last]), 5);
    } else {
      d = ic.decompress(dec, mulWrap(kGpsMultiMinus, diff[last]), 6);
      countExtreme(d);
    }
  }
  time[last] += uint64_t(int64_t(d));
}

// A switch to another sequence is followed by the time in that sequence; an encoder never switches
// twice for one point, so more hops than sequences means corrupt data.
inline constexpr int kMaxSequenceHops = 4;

// GPS time as a double (8 B).
class GpsTime11Decoder {
public:
  // Up to five sequence symbols (a fifth switch is corrupt), then a full time: the high word (4 steps)
  // and the low word raw (2).
  static constexpr size_t kMaxSymbols = 5 + 4 + 2;
  GpsTime11Decoder();
  void init(const uint8_t* item);
  template <class Decoder> void read(Decoder& dec, uint8_t* item);

private:
  SymbolModel multi_;
  SymbolModel zeroDiff_{6};
  IntegerCodec gpsTime_{32, 9};
  GpsSequences seq_;
};

// One color of RGB12 v2 and RGB14 v3 (the same coding): byteUsed says which bytes changed, diff[0..5]
// model the changes of red low/high, green low/high, blue low/high. byteUsed bits: 0/1 red low/high
// byte changed, 2/3 green, 4/5 blue, 6 the channels differ (else green and blue equal red). Green is
// predicted by red's change, blue by the mean of red's and green's.
template <class Decoder>
[[gnu::always_inline]] inline void decodeRgb(Decoder& dec, SymbolModel& byteUsed, SymbolModel* diff,
                                             const uint16_t* last, uint16_t* out) {
  const uint32_t sym = dec.decodeSymbol(byteUsed);
  auto low = [](uint32_t v) { return int32_t(v & 0xFF); };
  auto high = [](uint32_t v) { return int32_t(v >> 8); };
  uint32_t r = sym & 1 ? foldByte(int32_t(dec.decodeSymbol(diff[0])) + low(last[0])) : last[0] & 0xFFu;
  r |= sym & 2 ? uint32_t(foldByte(int32_t(dec.decodeSymbol(diff[1])) + high(last[0]))) << 8
               : last[0] & 0xFF00u;
  uint32_t g, b;
  if (sym & 64) {
    int32_t d = low(r) - low(last[0]);
    g = sym & 4 ? foldByte(int32_t(dec.decodeSymbol(diff[2])) + clampByte(d + low(last[1])))
                : last[1] & 0xFFu;
    if (sym & 16) {
      const int32_t corr = int32_t(dec.decodeSymbol(diff[4]));
      d = (d + (low(g) - low(last[1]))) / 2;
      b = foldByte(corr + clampByte(d + low(last[2])));
    } else {
      b = last[2] & 0xFFu;
    }
    d = high(r) - high(last[0]);
    g |= sym & 8 ? uint32_t(foldByte(int32_t(dec.decodeSymbol(diff[3])) + clampByte(d + high(last[1])))) << 8
                 : last[1] & 0xFF00u;
    if (sym & 32) {
      const int32_t corr = int32_t(dec.decodeSymbol(diff[5]));
      d = (d + (high(g) - high(last[1]))) / 2;
      b |= uint32_t(foldByte(corr + clampByte(d + high(last[2])))) << 8;
    } else {
      b |= last[2] & 0xFF00u;
    }
  } else {
    g = b = r;
  }
  out[0] = static_cast<uint16_t>(r);
  out[1] = static_cast<uint16_t>(g);
  out[2] = static_cast<uint16_t>(b);
}

// Red, green, blue as 16-bit values (6 B), coded byte by byte with the red change predicting the others.
class Rgb12Decoder {
public:
  static constexpr size_t kMaxSymbols = 7; // byte used, six byte differences
  Rgb12Decoder();
  void init(const uint8_t* item);
  template <class Decoder> void read(Decoder& dec, uint8_t* item);

private:
  SymbolModel byteUsed_{128};
  SymbolModel diff_[6] = {SymbolModel(256), SymbolModel(256), SymbolModel(256),
                          SymbolModel(256), SymbolModel(256), SymbolModel(256)};
  uint16_t last_[3] = {};
};

// Extra bytes: each byte the difference to the previous point's byte, one model per byte position.
class Byte2Decoder {
public:
  explicit Byte2Decoder(uint32_t count);
  size_t maxSymbols() const { return last_.size(); } // one a byte
  void init(const uint8_t* item);
  template <class Decoder> void read(Decoder& dec, uint8_t* item);

private:
  ContextModels models_; // one per byte position, created at first use
  std::vector<uint8_t> last_;
};

// A pointwise chunk: the first point raw, then one arithmetic-coded stream of all items of all other
// points. The items of a point format 0-3 record are fixed (POINT10, then GPSTIME11 and RGB12 where
// the format has them, then extra bytes), so the loop is compiled once per combination with every item
// decoder inlined and the coder's state in registers. The points that cannot reach the end of the
// stream (all but the last few dozen bytes' worth) decode without an end check per symbol.
class PointwiseChunkDecoder {
public:
  explicit PointwiseChunkDecoder(const Layout& layout);
  ~PointwiseChunkDecoder();
  // out: count raw records (see ChunkDecoder::decode). Throws CorruptChunk.
  void decode(const uint8_t* data, size_t size, uint64_t count, std::vector<uint8_t>& out);

private:
  template <bool kGps, bool kRgb, bool kBytes>
  void decodeLoop(const uint8_t* data, size_t size, uint64_t count, std::vector<uint8_t>& out);
  template <bool kGps, bool kRgb, bool kBytes, class Decoder> void readPoint(Decoder& dec, uint8_t* record);

  size_t recordLength_;
  size_t maxSymbols_ = Point10Decoder::kMaxSymbols; // a point's, all items
  Point10Decoder point_;
  std::unique_ptr<GpsTime11Decoder> gps_;
  std::unique_ptr<Rgb12Decoder> rgb_;
  std::unique_ptr<Byte2Decoder> bytes_;
  size_t gpsOffset_ = 0, rgbOffset_ = 0, bytesOffset_ = 0;
};

} // namespace pointrast::io::laz
