#include "io/las/laz_pointwise.h"

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

template <class Decoder>
[[gnu::always_inline]] inline void Point10Decoder::read(Decoder& dec, uint8_t* item) {
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

template <class Decoder>
[[gnu::always_inline]] inline void GpsTime11Decoder::read(Decoder& dec, uint8_t* item) {
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

Rgb12Decoder::Rgb12Decoder() = default;

void Rgb12Decoder::init(const uint8_t* item) {
  byteUsed_.reset();
  for (SymbolModel& m : diff_)
    m.reset();
  for (int c = 0; c < 3; ++c)
    last_[c] = loadLE<uint16_t>(item + 2 * c);
}

template <class Decoder> [[gnu::always_inline]] inline void Rgb12Decoder::read(Decoder& dec, uint8_t* item) {
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

template <class Decoder> [[gnu::always_inline]] inline void Byte2Decoder::read(Decoder& dec, uint8_t* item) {
  for (size_t i = 0; i < last_.size(); ++i) {
    last_[i] = foldByte(int32_t(last_[i]) + int32_t(dec.decodeSymbol(models_[i])));
    item[i] = last_[i];
  }
}

// ---- the chunk ----------------------------------------------------------------------------------------

PointwiseChunkDecoder::PointwiseChunkDecoder(const Layout& layout) : recordLength_(layout.recordLength) {
  size_t offset = 0;
  for (const Item& item : layout.items) {
    // parseLaszipVlr admits these items in this order only.
    if (item.type == ItemType::GpsTime11) {
      gps_ = std::make_unique<GpsTime11Decoder>();
      gpsOffset_ = offset;
      maxSymbols_ += GpsTime11Decoder::kMaxSymbols;
    } else if (item.type == ItemType::Rgb12) {
      rgb_ = std::make_unique<Rgb12Decoder>();
      rgbOffset_ = offset;
      maxSymbols_ += Rgb12Decoder::kMaxSymbols;
    } else if (item.type == ItemType::Byte) {
      bytes_ = std::make_unique<Byte2Decoder>(item.size);
      bytesOffset_ = offset;
      maxSymbols_ += bytes_->maxSymbols();
    }
    offset += item.size;
  }
}

PointwiseChunkDecoder::~PointwiseChunkDecoder() = default;

template <bool kGps, bool kRgb, bool kBytes, class Decoder>
[[gnu::always_inline]] inline void PointwiseChunkDecoder::readPoint(Decoder& dec, uint8_t* record) {
  point_.read(dec, record);
  if constexpr (kGps) gps_->read(dec, record + gpsOffset_);
  if constexpr (kRgb) rgb_->read(dec, record + rgbOffset_);
  if constexpr (kBytes) bytes_->read(dec, record + bytesOffset_);
}

template <bool kGps, bool kRgb, bool kBytes>
void PointwiseChunkDecoder::decodeLoop(const uint8_t* data, size_t size, uint64_t count,
                                       std::vector<uint8_t>& out) {
  const size_t rl = recordLength_;
  uint64_t capacity = initialRecordCapacity(count, size);
  out.resize(capacity * rl);
  std::memcpy(out.data(), data, rl);
  point_.init(data);
  if constexpr (kGps) gps_->init(data + gpsOffset_);
  if constexpr (kRgb) rgb_->init(data + rgbOffset_);
  if constexpr (kBytes) bytes_->init(data + bytesOffset_);
  // A local coder: its address never escapes the inlined item decoders, so its state stays in
  // registers instead of round-tripping through memory between symbols.
  ArithmeticDecoder dec;
  dec.init(data + rl, data + size);
  uint64_t i = 1;
  if (count > 1 && dec.hasRoom(maxSymbols_)) {
    // While a whole point fits before the end of the stream: no end check a symbol, and no bytes past
    // the end to count. Its state goes on in the checked coder for the last points. The output grows
    // outside the inner loop.
    const uint8_t* const lastStart = data + size - kMaxBytesPerSymbol * maxSymbols_ - 1;
    UncheckedDecoder fast(dec);
    do {
      uint8_t* record = recordSlot(out, i, capacity, rl, count);
      uint8_t* const recordsEnd = out.data() + capacity * rl;
      do {
        readPoint<kGps, kRgb, kBytes>(fast, record);
        record += rl;
      } while (record != recordsEnd && fast.position() <= lastStart);
      i = uint64_t(record - out.data()) / rl;
    } while (i < count && fast.position() <= lastStart);
    dec = ArithmeticDecoder(fast);
  }
  for (; i < count; ++i) {
    readPoint<kGps, kRgb, kBytes>(dec, recordSlot(out, i, capacity, rl, count));
    if (dec.pastEnd() > kPastEndSlack) corrupt("its data ends before its last point");
  }
}

void PointwiseChunkDecoder::decode(const uint8_t* data, size_t size, uint64_t count,
                                   std::vector<uint8_t>& out) {
  if (size < recordLength_) corrupt("its data ends inside the first point");
  const int combination = (gps_ ? 4 : 0) | (rgb_ ? 2 : 0) | (bytes_ ? 1 : 0);
  switch (combination) {
  case 0:
    return decodeLoop<false, false, false>(data, size, count, out);
  case 1:
    return decodeLoop<false, false, true>(data, size, count, out);
  case 2:
    return decodeLoop<false, true, false>(data, size, count, out);
  case 3:
    return decodeLoop<false, true, true>(data, size, count, out);
  case 4:
    return decodeLoop<true, false, false>(data, size, count, out);
  case 5:
    return decodeLoop<true, false, true>(data, size, count, out);
  case 6:
    return decodeLoop<true, true, false>(data, size, count, out);
  default:
    return decodeLoop<true, true, true>(data, size, count, out);
  }
}

} // namespace pointrast::io::laz
