#include "io/laz_pointwise.h"

#include <cstring>

#include "io/io_util.h"

namespace pointrast::io::laz {

using detail::loadLE;
using detail::storeLE;

// ---- POINT10 v2 ---------------------------------------------------------------------------------------
// Raw layout: X, Y, Z int32 at 0, 4, 8; intensity uint16 at 12; byte 14: return number (bits 0-2),
// number of returns (3-5), scan direction (6), edge of flight line (7); classification at 15; scan
// angle rank at 16; user data at 17; point source id uint16 at 18.

Point10Decoder::Point10Decoder() = default;

void Point10Decoder::init(const uint8_t* item) {
  for (int i = 0; i < 16; ++i) {
    lastXDiff_[i].reset();
    lastYDiff_[i].reset();
    lastIntensity_[i] = 0;
  }
  for (int32_t& h : lastHeight_)
    h = 0;
  changedValues_.reset();
  intensity_.reset();
  scanAngleRank_[0].reset();
  scanAngleRank_[1].reset();
  pointSourceId_.reset();
  bitByte_.invalidate();
  classification_.invalidate();
  userData_.invalidate();
  dx_.reset();
  dy_.reset();
  z_.reset();
  std::memcpy(last_, item, 20);
  // LASzip predicts the second point's intensity from 0, not from the first point.
  last_[12] = last_[13] = 0;
}

void Point10Decoder::read(ArithmeticDecoder& dec, uint8_t* item) {
  // Bits of changedValues: 32 return byte, 16 intensity, 8 classification, 4 scan angle rank,
  // 2 user data, 1 point source id.
  const uint32_t changed = dec.decodeSymbol(changedValues_);
  if (changed & 32) last_[14] = static_cast<uint8_t>(dec.decodeSymbol(bitByte_[last_[14]]));
  const uint32_t r = last_[14] & 7;
  const uint32_t n = (last_[14] >> 3) & 7;
  const uint32_t m = kReturnMap[n][r];
  const uint32_t l = returnLevel(n, r);
  if (changed) {
    if (changed & 16) {
      const uint16_t intensity =
          static_cast<uint16_t>(intensity_.decompress(dec, lastIntensity_[m], m < 3 ? m : 3));
      lastIntensity_[m] = intensity;
      storeLE<uint16_t>(last_ + 12, intensity);
    } else {
      storeLE<uint16_t>(last_ + 12, lastIntensity_[m]);
    }
    if (changed & 8) last_[15] = static_cast<uint8_t>(dec.decodeSymbol(classification_[last_[15]]));
    if (changed & 4) {
      const uint32_t delta = dec.decodeSymbol(scanAngleRank_[(last_[14] >> 6) & 1]);
      last_[16] = static_cast<uint8_t>(delta + last_[16]);
    }
    if (changed & 2) last_[17] = static_cast<uint8_t>(dec.decodeSymbol(userData_[last_[17]]));
    if (changed & 1)
      storeLE<uint16_t>(last_ + 18,
                        static_cast<uint16_t>(pointSourceId_.decompress(dec, loadLE<uint16_t>(last_ + 18))));
  }

  // X and Y: the difference to the last point, predicted by the median of the last five differences of
  // points with the same return context; Y's context adds the bits X's difference needed, Z's those of
  // both.
  const int32_t dx = dx_.decompress(dec, lastXDiff_[m].get(), n == 1);
  storeLE<int32_t>(last_, addWrap(loadLE<int32_t>(last_), dx));
  lastXDiff_[m].add(dx);
  uint32_t kBits = dx_.getK();
  const int32_t dy = dy_.decompress(dec, lastYDiff_[m].get(), (n == 1) + (kBits < 20 ? (kBits & ~1u) : 20));
  storeLE<int32_t>(last_ + 4, addWrap(loadLE<int32_t>(last_ + 4), dy));
  lastYDiff_[m].add(dy);
  kBits = (dx_.getK() + dy_.getK()) / 2;
  const int32_t z = z_.decompress(dec, lastHeight_[l], (n == 1) + (kBits < 18 ? (kBits & ~1u) : 18));
  storeLE<int32_t>(last_ + 8, z);
  lastHeight_[l] = z;
  std::memcpy(item, last_, 20);
}

// ---- GPS time sequences ---------------------------------------------------------------------------
// Multiplier symbols shared by both generations: 1..499 that multiple of the last difference, 500 a
// large multiple, 501..510 the multiples -1..-10, 0 a difference unrelated to the last one. A multiplier
// at an extreme (0, 500, -10) four times in a row replaces the sequence's difference.

namespace {
constexpr uint32_t kGpsMulti = 500;
constexpr int32_t kGpsMultiMinus = -10;
} // namespace

void GpsSequences::readFirstDiff(ArithmeticDecoder& dec, IntegerCodec& ic) {
  diff[last] = ic.decompress(dec, 0, 0);
  time[last] += uint64_t(int64_t(diff[last]));
  extremeCounter[last] = 0;
}

void GpsSequences::readFull(ArithmeticDecoder& dec, IntegerCodec& ic) {
  next = (next + 1) & 3;
  const uint32_t high = uint32_t(ic.decompress(dec, int32_t(uint32_t(time[last] >> 32)), 8));
  time[next] = (uint64_t(high) << 32) | dec.readInt();
  last = next;
  diff[last] = 0;
  extremeCounter[last] = 0;
}

void GpsSequences::readSameDiff(ArithmeticDecoder& dec, IntegerCodec& ic) {
  time[last] += uint64_t(int64_t(ic.decompress(dec, diff[last], 1)));
  extremeCounter[last] = 0;
}

void GpsSequences::readMultiple(ArithmeticDecoder& dec, IntegerCodec& ic, uint32_t multi) {
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

// ---- GPSTIME11 v2 -------------------------------------------------------------------------------------
// After a zero difference (6 symbols): 0 unchanged, 1 a new difference, 2 a full time, 3..5 a switch to
// sequence last + 1..3. Otherwise (516 symbols): the multipliers above, 511 unchanged, 512 a full time,
// 513..515 a switch.

namespace {
constexpr uint32_t kGps2Unchanged = 511;
constexpr uint32_t kGps2CodeFull = 512;
constexpr uint32_t kGps2Symbols = 516;
} // namespace

GpsTime11Decoder::GpsTime11Decoder() : multi_(kGps2Symbols) {}

void GpsTime11Decoder::init(const uint8_t* item) {
  multi_.reset();
  zeroDiff_.reset();
  gpsTime_.reset();
  seq_.reset(loadLE<uint64_t>(item));
}

void GpsTime11Decoder::read(ArithmeticDecoder& dec, uint8_t* item) {
  for (int hop = 0;; ++hop) {
    if (hop > kMaxSequenceHops) corrupt("its GPS times switch sequences without end");
    if (seq_.diff[seq_.last] == 0) {
      const uint32_t multi = dec.decodeSymbol(zeroDiff_);
      if (multi == 1) {
        seq_.readFirstDiff(dec, gpsTime_);
      } else if (multi == 2) {
        seq_.readFull(dec, gpsTime_);
      } else if (multi > 2) {
        seq_.last = (seq_.last + multi - 2) & 3;
        continue;
      }
    } else {
      const uint32_t multi = dec.decodeSymbol(multi_);
      if (multi == 1) {
        seq_.readSameDiff(dec, gpsTime_);
      } else if (multi < kGps2Unchanged) {
        seq_.readMultiple(dec, gpsTime_, multi);
      } else if (multi == kGps2CodeFull) {
        seq_.readFull(dec, gpsTime_);
      } else if (multi > kGps2CodeFull) {
        seq_.last = (seq_.last + multi - kGps2CodeFull) & 3;
        continue;
      }
    }
    break;
  }
  storeLE<uint64_t>(item, seq_.current());
}

// ---- RGB12 v2 -----------------------------------------------------------------------------------------
// byteUsed bits: 0/1 red low/high byte changed, 2/3 green, 4/5 blue, 6 the channels differ (else green
// and blue equal red). Green is predicted by red's change, blue by the mean of red's and green's.

void decodeRgb(ArithmeticDecoder& dec, SymbolModel& byteUsed, SymbolModel* diff, const uint16_t* last,
               uint16_t* out) {
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

Rgb12Decoder::Rgb12Decoder() = default;

void Rgb12Decoder::init(const uint8_t* item) {
  byteUsed_.reset();
  for (SymbolModel& m : diff_)
    m.reset();
  for (int c = 0; c < 3; ++c)
    last_[c] = loadLE<uint16_t>(item + 2 * c);
}

void Rgb12Decoder::read(ArithmeticDecoder& dec, uint8_t* item) {
  uint16_t rgb[3];
  decodeRgb(dec, byteUsed_, diff_, last_, rgb);
  for (int c = 0; c < 3; ++c) {
    storeLE<uint16_t>(item + 2 * c, rgb[c]);
    last_[c] = rgb[c];
  }
}

// ---- BYTE v2 ------------------------------------------------------------------------------------------

Byte2Decoder::Byte2Decoder(uint32_t count) : models_(count, 256), last_(count) {}

void Byte2Decoder::init(const uint8_t* item) {
  models_.invalidate();
  std::memcpy(last_.data(), item, last_.size());
}

void Byte2Decoder::read(ArithmeticDecoder& dec, uint8_t* item) {
  for (size_t i = 0; i < last_.size(); ++i) {
    last_[i] = foldByte(int32_t(last_[i]) + int32_t(dec.decodeSymbol(models_[i])));
    item[i] = last_[i];
  }
}

} // namespace pointrast::io::laz
