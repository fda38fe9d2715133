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

#include "io/laz_arithmetic.h"
#include "io/laz_common.h"
#include "io/laz_integer.h"

namespace pointrast::io::laz {

// A model per possible previous byte value, created on first use (most files use a handful).
class ContextModels {
public:
  ContextModels(size_t contexts, uint32_t symbols) : models_(contexts), symbols_(symbols) {}
  SymbolModel& operator[](size_t context) {
    SymbolModel& m = models_[context];
    if (!m.created()) m.create(symbols_);
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
};

// X, Y, Z, intensity, return bits, classification, scan angle rank, user data, point source id (20 B).
class Point10Decoder {
public:
  Point10Decoder();
  void init(const uint8_t* item);
  void read(ArithmeticDecoder& dec, uint8_t* item);

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
  void readFirstDiff(ArithmeticDecoder& dec, IntegerCodec& ic);
  // A full time: the high word predicted by the current time's, the low word raw; starts a sequence.
  void readFull(ArithmeticDecoder& dec, IntegerCodec& ic);
  // Multiplier symbol 0..510 (never 1, which callers handle as "the last difference again").
  void readMultiple(ArithmeticDecoder& dec, IntegerCodec& ic, uint32_t multi);
  void readSameDiff(ArithmeticDecoder& dec, IntegerCodec& ic);
};

// A switch to another sequence is followed by the time in that sequence; an encoder never switches
// twice for one point, so more hops than sequences means corrupt data.
inline constexpr int kMaxSequenceHops = 4;

// GPS time as a double (8 B).
class GpsTime11Decoder {
public:
  GpsTime11Decoder();
  void init(const uint8_t* item);
  void read(ArithmeticDecoder& dec, uint8_t* item);

private:
  SymbolModel multi_;
  SymbolModel zeroDiff_{6};
  IntegerCodec gpsTime_{32, 9};
  GpsSequences seq_;
};

// One color of RGB12 v2 and RGB14 v3 (the same coding): byteUsed says which bytes changed, diff[0..5]
// model the changes of red low/high, green low/high, blue low/high.
void decodeRgb(ArithmeticDecoder& dec, SymbolModel& byteUsed, SymbolModel* diff, const uint16_t* last,
               uint16_t* out);

// Red, green, blue as 16-bit values (6 B), coded byte by byte with the red change predicting the others.
class Rgb12Decoder {
public:
  Rgb12Decoder();
  void init(const uint8_t* item);
  void read(ArithmeticDecoder& dec, uint8_t* item);

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
  void init(const uint8_t* item);
  void read(ArithmeticDecoder& dec, uint8_t* item);

private:
  ContextModels models_; // one per byte position, created at first use
  std::vector<uint8_t> last_;
};

} // namespace pointrast::io::laz
