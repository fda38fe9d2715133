#include "io/las/laz_encoder.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <mutex>
#include <span>

#include "base/parallel.h"
#include "io/io_util.h"
#include "io/las/laz_arithmetic.h"
#include "io/las/laz_common.h"
#include "io/las/laz_integer.h"
#include "io/las/laz_layered.h"
#include "io/las/laz_pointwise.h"

namespace pointrast::io::laz {

using detail::loadLE;
using detail::storeLE;

namespace {

// The encoders' models keep no decoder tables (laz_arithmetic.h).
constexpr ModelUse kEncode = ModelUse::Encode;

bool fitsInt32(int64_t v) {
  return v >= INT32_MIN && v <= INT32_MAX;
}

// ---- GPS time sequences, both generations --------------------------------------------------------------
// The codes of GpsSequences (laz_pointwise.h) from the encoder's side. `symbols` names the generation's
// numbering: v2 has an "unchanged" symbol in both states, v3 none (its XY layer says the time changed).
struct GpsSymbols {
  bool hasUnchanged;
  uint32_t zeroUnchanged, zeroNewDiff, zeroFull, zeroSwitch; // zeroSwitch + i - 1: sequence last + i
  uint32_t multiUnchanged, multiFull, multiSwitch;           // multiSwitch + i - 1
};
constexpr GpsSymbols kGpsV2{true, 0, 1, 2, 3, 511, 512, 513};
constexpr GpsSymbols kGpsV3{false, 0, 0, 1, 2, 0, 511, 512};

// A 32-bit difference d coded against the sequence's last difference (nonzero): the multiplier closest
// to d / last, then the corrector against that multiple; the decoder's readSameDiff / readMultiple.
void writeMultiple(ArithmeticEncoder& enc, SymbolModel& multiModel, IntegerCodec& ic, GpsSequences& s,
                   int32_t d) {
  const int32_t last = s.diff[s.last];
  const double ratio = double(d) / double(last);
  const int64_t multi = std::isfinite(ratio) ? int64_t(std::llround(std::clamp(ratio, -1e6, 1e6))) : 0;
  auto countExtreme = [&] {
    if (++s.extremeCounter[s.last] > 3) {
      s.diff[s.last] = d;
      s.extremeCounter[s.last] = 0;
    }
  };
  if (multi == 1) {
    enc.encodeSymbol(multiModel, 1);
    ic.compress(enc, last, d, 1);
    s.extremeCounter[s.last] = 0;
  } else if (multi > 1 && multi < kGpsMulti) {
    enc.encodeSymbol(multiModel, uint32_t(multi));
    ic.compress(enc, mulWrap(int32_t(multi), last), d, multi < 10 ? 2 : 3);
  } else if (multi >= kGpsMulti) {
    enc.encodeSymbol(multiModel, kGpsMulti);
    ic.compress(enc, mulWrap(int32_t(kGpsMulti), last), d, 4);
    countExtreme();
  } else if (multi < 0 && multi > kGpsMultiMinus) {
    enc.encodeSymbol(multiModel, uint32_t(int64_t(kGpsMulti) - multi));
    ic.compress(enc, mulWrap(int32_t(multi), last), d, 5);
  } else if (multi < 0) {
    enc.encodeSymbol(multiModel, uint32_t(int32_t(kGpsMulti) - kGpsMultiMinus));
    ic.compress(enc, mulWrap(kGpsMultiMinus, last), d, 6);
    countExtreme();
  } else {
    enc.encodeSymbol(multiModel, 0);
    ic.compress(enc, 0, d, 7);
    countExtreme();
  }
  s.time[s.last] += uint64_t(int64_t(d));
}

// One GPS time (the double's bits) into the sequences; the decoder's read loop in reverse. A switch to
// another sequence happens only when that sequence's time is within 32 bits, so it is never followed by
// another switch.
void writeGpsTime(ArithmeticEncoder& enc, const GpsSymbols& sym, SymbolModel& zeroModel,
                  SymbolModel& multiModel, IntegerCodec& ic, GpsSequences& s, uint64_t t) {
  for (int hop = 0; hop < 2; ++hop) {
    const bool zeroDiff = s.diff[s.last] == 0;
    SymbolModel& model = zeroDiff ? zeroModel : multiModel;
    if (t == s.time[s.last] && sym.hasUnchanged) {
      enc.encodeSymbol(model, zeroDiff ? sym.zeroUnchanged : sym.multiUnchanged);
      return;
    }
    const int64_t d = int64_t(t - s.time[s.last]);
    if (fitsInt32(d)) {
      if (zeroDiff) {
        enc.encodeSymbol(model, sym.zeroNewDiff);
        ic.compress(enc, 0, int32_t(d), 0);
        s.diff[s.last] = int32_t(d);
        s.time[s.last] = t;
        s.extremeCounter[s.last] = 0;
      } else {
        writeMultiple(enc, multiModel, ic, s, int32_t(d));
      }
      return;
    }
    if (hop == 0) {
      bool switched = false;
      for (uint32_t i = 1; i < 4 && !switched; ++i) {
        const uint32_t other = (s.last + i) & 3;
        if (fitsInt32(int64_t(t - s.time[other]))) {
          enc.encodeSymbol(model, (zeroDiff ? sym.zeroSwitch : sym.multiSwitch) + i - 1);
          s.last = other;
          switched = true;
        }
      }
      if (switched) continue;
    }
    // A full time starts a new sequence: the high word predicted by the current time's, the low raw.
    enc.encodeSymbol(model, zeroDiff ? sym.zeroFull : sym.multiFull);
    s.next = (s.next + 1) & 3;
    ic.compress(enc, int32_t(uint32_t(s.time[s.last] >> 32)), int32_t(uint32_t(t >> 32)), 8);
    enc.writeBits(32, uint32_t(t));
    s.last = s.next;
    s.time[s.last] = t;
    s.diff[s.last] = 0;
    s.extremeCounter[s.last] = 0;
    return;
  }
}

// ---- RGB, both generations ------------------------------------------------------------------------------
// decodeRgb (laz_pointwise.h) in reverse: the byteUsed symbol, then each changed byte as the difference
// to its prediction, in the decoder's order.
void encodeRgb(ArithmeticEncoder& enc, SymbolModel& byteUsed, SymbolModel* diff, const uint16_t* last,
               const uint16_t* rgb) {
  auto low = [](uint32_t v) { return int32_t(v & 0xFF); };
  auto high = [](uint32_t v) { return int32_t(v >> 8); };
  const uint32_t r = rgb[0], g = rgb[1], b = rgb[2];
  uint32_t sym = 0;
  if (low(r) != low(last[0])) sym |= 1;
  if (high(r) != high(last[0])) sym |= 2;
  if (r != g || r != b) {
    sym |= 64;
    if (low(g) != low(last[1])) sym |= 4;
    if (low(b) != low(last[2])) sym |= 16;
    if (high(g) != high(last[1])) sym |= 8;
    if (high(b) != high(last[2])) sym |= 32;
  }
  enc.encodeSymbol(byteUsed, sym);
  auto put = [&](SymbolModel& m, int32_t value, int32_t prediction) {
    enc.encodeSymbol(m, uint32_t(value - prediction) & 0xFF);
  };
  if (sym & 1) put(diff[0], low(r), low(last[0]));
  if (sym & 2) put(diff[1], high(r), high(last[0]));
  if (!(sym & 64)) return;
  int32_t d = low(r) - low(last[0]);
  if (sym & 4) put(diff[2], low(g), clampByte(d + low(last[1])));
  if (sym & 16) put(diff[4], low(b), clampByte((d + (low(g) - low(last[1]))) / 2 + low(last[2])));
  d = high(r) - high(last[0]);
  if (sym & 8) put(diff[3], high(g), clampByte(d + high(last[1])));
  if (sym & 32) put(diff[5], high(b), clampByte((d + (high(g) - high(last[1]))) / 2 + high(last[2])));
}

} // namespace

// ---- pointwise, version 2 -------------------------------------------------------------------------------

class Point10Encoder {
public:
  void init(const uint8_t* item) {
    for (int i = 0; i < 16; ++i) {
      lastXDiff_[i].reset();
      lastYDiff_[i].reset();
      lastIntensity_[i] = 0;
    }
    std::fill(std::begin(lastHeight_), std::end(lastHeight_), 0);
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
    last_[12] = last_[13] = 0; // the second point's intensity is predicted from 0, as the decoder does
  }

  void write(ArithmeticEncoder& enc, const uint8_t* item) {
    const uint8_t returns = item[14];
    const uint32_t r = returns & 7, n = (returns >> 3) & 7;
    const uint32_t m = kReturnMap[n][r], l = returnLevel(n, r);
    const uint16_t intensity = loadLE<uint16_t>(item + 12);
    const uint16_t pointSource = loadLE<uint16_t>(item + 18);
    const uint32_t changed = (returns != last_[14] ? 32 : 0) | (intensity != lastIntensity_[m] ? 16 : 0) |
                             (item[15] != last_[15] ? 8 : 0) | (item[16] != last_[16] ? 4 : 0) |
                             (item[17] != last_[17] ? 2 : 0) |
                             (pointSource != loadLE<uint16_t>(last_ + 18) ? 1 : 0);
    enc.encodeSymbol(changedValues_, changed);
    if (changed & 32) enc.encodeSymbol(bitByte_[last_[14]], returns);
    last_[14] = returns;
    if (changed & 16) {
      intensity_.compress(enc, lastIntensity_[m], intensity, m < 3 ? m : 3);
      lastIntensity_[m] = intensity;
    }
    if (changed & 8) enc.encodeSymbol(classification_[last_[15]], item[15]);
    if (changed & 4) enc.encodeSymbol(scanAngleRank_[(returns >> 6) & 1], uint8_t(item[16] - last_[16]));
    if (changed & 2) enc.encodeSymbol(userData_[last_[17]], item[17]);
    if (changed & 1) pointSourceId_.compress(enc, loadLE<uint16_t>(last_ + 18), pointSource);

    const int32_t x = loadLE<int32_t>(item), y = loadLE<int32_t>(item + 4), z = loadLE<int32_t>(item + 8);
    const int32_t dx = int32_t(uint32_t(x) - uint32_t(loadLE<int32_t>(last_)));
    dx_.compress(enc, lastXDiff_[m].get(), dx, n == 1);
    lastXDiff_[m].add(dx);
    uint32_t kBits = dx_.getK();
    const int32_t dy = int32_t(uint32_t(y) - uint32_t(loadLE<int32_t>(last_ + 4)));
    dy_.compress(enc, lastYDiff_[m].get(), dy, (n == 1) + (kBits < 20 ? (kBits & ~1u) : 20));
    lastYDiff_[m].add(dy);
    kBits = (dx_.getK() + dy_.getK()) / 2;
    z_.compress(enc, lastHeight_[l], z, (n == 1) + (kBits < 18 ? (kBits & ~1u) : 18));
    lastHeight_[l] = z;
    std::memcpy(last_, item, 20);
  }

private:
  SymbolModel changedValues_{64, kEncode};
  IntegerCodec intensity_{16, 4, kEncode};
  SymbolModel scanAngleRank_[2] = {SymbolModel(256, kEncode), SymbolModel(256, kEncode)};
  IntegerCodec pointSourceId_{16, 1, kEncode};
  ContextModels bitByte_{256, 256, kEncode}, classification_{256, 256, kEncode}, userData_{256, 256, kEncode};
  IntegerCodec dx_{32, 2, kEncode}, dy_{32, 22, kEncode}, z_{32, 20, kEncode};
  uint8_t last_[20] = {};
  uint16_t lastIntensity_[16] = {};
  Median5 lastXDiff_[16], lastYDiff_[16];
  int32_t lastHeight_[8] = {};
};

class GpsTime11Encoder {
public:
  void init(const uint8_t* item) {
    multi_.reset();
    zeroDiff_.reset();
    gpsTime_.reset();
    seq_.reset(loadLE<uint64_t>(item));
  }
  void write(ArithmeticEncoder& enc, const uint8_t* item) {
    writeGpsTime(enc, kGpsV2, zeroDiff_, multi_, gpsTime_, seq_, loadLE<uint64_t>(item));
  }

private:
  SymbolModel multi_{516, kEncode};
  SymbolModel zeroDiff_{6};
  IntegerCodec gpsTime_{32, 9, kEncode};
  GpsSequences seq_;
};

class Rgb12Encoder {
public:
  void init(const uint8_t* item) {
    byteUsed_.reset();
    for (SymbolModel& m : diff_)
      m.reset();
    for (int c = 0; c < 3; ++c)
      last_[c] = loadLE<uint16_t>(item + 2 * c);
  }
  void write(ArithmeticEncoder& enc, const uint8_t* item) {
    uint16_t rgb[3];
    for (int c = 0; c < 3; ++c)
      rgb[c] = loadLE<uint16_t>(item + 2 * c);
    encodeRgb(enc, byteUsed_, diff_, last_, rgb);
    std::copy(rgb, rgb + 3, last_);
  }

private:
  SymbolModel byteUsed_{128, kEncode};
  SymbolModel diff_[6] = {SymbolModel(256, kEncode), SymbolModel(256, kEncode), SymbolModel(256, kEncode),
                          SymbolModel(256, kEncode), SymbolModel(256, kEncode), SymbolModel(256, kEncode)};
  uint16_t last_[3] = {};
};

class Byte2Encoder {
public:
  explicit Byte2Encoder(uint32_t count) : models_(count, 256, kEncode), last_(count) {}
  void init(const uint8_t* item) {
    models_.invalidate();
    std::memcpy(last_.data(), item, last_.size());
  }
  void write(ArithmeticEncoder& enc, const uint8_t* item) {
    for (size_t i = 0; i < last_.size(); ++i) {
      enc.encodeSymbol(models_[i], uint8_t(item[i] - last_[i]));
      last_[i] = item[i];
    }
  }

private:
  ContextModels models_;
  std::vector<uint8_t> last_;
};

// The first record raw, then one arithmetic-coded stream of every item of every other record.
class PointwiseChunkEncoder {
public:
  explicit PointwiseChunkEncoder(const Layout& layout) : recordLength_(layout.recordLength) {
    size_t offset = 0;
    for (const Item& item : layout.items) {
      if (item.type == ItemType::GpsTime11) {
        gps_ = std::make_unique<GpsTime11Encoder>();
        gpsOffset_ = offset;
      } else if (item.type == ItemType::Rgb12) {
        rgb_ = std::make_unique<Rgb12Encoder>();
        rgbOffset_ = offset;
      } else if (item.type == ItemType::Byte) {
        bytes_ = std::make_unique<Byte2Encoder>(item.size);
        bytesOffset_ = offset;
      }
      offset += item.size;
    }
  }

  std::vector<uint8_t> encode(const uint8_t* records, uint64_t count) {
    const size_t rl = recordLength_;
    point_.init(records);
    if (gps_) gps_->init(records + gpsOffset_);
    if (rgb_) rgb_->init(records + rgbOffset_);
    if (bytes_) bytes_->init(records + bytesOffset_);
    ArithmeticEncoder& enc = enc_;
    for (uint64_t i = 1; i < count; ++i) {
      const uint8_t* record = records + i * rl;
      point_.write(enc, record);
      if (gps_) gps_->write(enc, record + gpsOffset_);
      if (rgb_) rgb_->write(enc, record + rgbOffset_);
      if (bytes_) bytes_->write(enc, record + bytesOffset_);
    }
    const std::span<const uint8_t> coded = enc.flush();
    std::vector<uint8_t> out(rl + coded.size());
    std::memcpy(out.data(), records, rl);
    std::memcpy(out.data() + rl, coded.data(), coded.size());
    return out;
  }

private:
  size_t recordLength_;
  Point10Encoder point_;
  std::unique_ptr<GpsTime11Encoder> gps_;
  std::unique_ptr<Rgb12Encoder> rgb_;
  std::unique_ptr<Byte2Encoder> bytes_;
  size_t gpsOffset_ = 0, rgbOffset_ = 0, bytesOffset_ = 0;
  ArithmeticEncoder enc_; // kept from chunk to chunk with its buffer
};

// ---- layered, version 3 ---------------------------------------------------------------------------------

namespace {

enum Point14Layer { kXY, kZ, kClassification, kFlags, kIntensity, kScanAngle, kUserData, kPointSource, kGps };
constexpr int kPoint14Layers = 9;

// A layer: its coder and whether any point's value differed from the value the decoder would keep
// without it. A layer nothing changed in is written empty, and the decoder keeps the last values.
// Its bytes stay in the coder's buffer until the chunk is put together.
struct LayerOut {
  ArithmeticEncoder enc;
  bool changed = false;
  std::span<const uint8_t> finish(bool keep) {
    const std::span<const uint8_t> bytes = enc.flush();
    return keep ? bytes : std::span<const uint8_t>();
  }
};

} // namespace

class Point14Encoder {
public:
  void init(const uint8_t* item, uint32_t& context) {
    for (auto& c : contexts_)
      if (c) c->unused = true;
    for (LayerOut& l : layers_)
      l.changed = false;
    const Point14 first = Point14::parse(item);
    current_ = first.scannerChannel;
    context = current_;
    createContext(current_, first);
  }

  void write(const uint8_t* item, uint32_t& context) {
    const Point14 p = Point14::parse(item);
    Point14* last = &contexts_[current_]->last;
    Context& old = *contexts_[current_];
    const uint32_t lpr = (last->returnNumber == 1 ? 1 : 0) +
                         (last->returnNumber >= last->numberOfReturns ? 2 : 0) +
                         (last->gpsTimeChange ? 4 : 0);
    const uint32_t previous = current_;
    const bool channelChange = p.scannerChannel != current_;
    if (channelChange) {
      const uint32_t channel = p.scannerChannel;
      if (!contexts_[channel] || contexts_[channel]->unused) createContext(channel, *last);
      current_ = channel;
      context = channel;
      last = &contexts_[current_]->last;
      last->scannerChannel = static_cast<uint8_t>(channel);
    }
    Context& c = *contexts_[current_];
    const bool pointSourceChange = p.pointSourceId != last->pointSourceId;
    const bool gpsTimeChange = p.gpsTime != last->gpsTime;
    const bool scanAngleChange = p.scanAngle != last->scanAngle;
    const bool returnsChange = p.numberOfReturns != last->numberOfReturns;
    const uint32_t rDiff = (uint32_t(p.returnNumber) - last->returnNumber) & 15;
    const uint32_t rCode = rDiff == 0 ? 0 : rDiff == 1 ? 1 : rDiff == 15 ? 2 : 3;
    const uint32_t changed = (channelChange ? 64 : 0) | (pointSourceChange ? 32 : 0) |
                             (gpsTimeChange ? 16 : 0) | (scanAngleChange ? 8 : 0) | (returnsChange ? 4 : 0) |
                             rCode;
    ArithmeticEncoder& xy = layers_[kXY].enc;
    xy.encodeSymbol(old.changedValues[lpr], changed);
    if (channelChange) xy.encodeSymbol(old.scannerChannel, (p.scannerChannel + 3 - previous) % 4);

    const uint32_t n = p.numberOfReturns, r = p.returnNumber;
    if (returnsChange) xy.encodeSymbol(c.numberOfReturns[last->numberOfReturns], n);
    if (rCode == 3) {
      if (gpsTimeChange)
        xy.encodeSymbol(c.returnNumber[last->returnNumber], r);
      else
        xy.encodeSymbol(c.returnNumberGpsSame, rDiff - 2);
    }
    const uint32_t m = kReturnMap6[n][r];
    const uint32_t l = returnLevel(n, r);
    const uint32_t cpr = (r == 1 ? 1 : 0) + (r >= n ? 2 : 0);
    const uint32_t xyIndex = (m << 1) | (gpsTimeChange ? 1 : 0);

    const int32_t dx = int32_t(uint32_t(p.x) - uint32_t(last->x));
    c.dx.compress(xy, c.lastXDiff[xyIndex].get(), dx, n == 1);
    c.lastXDiff[xyIndex].add(dx);
    uint32_t kBits = c.dx.getK();
    const int32_t dy = int32_t(uint32_t(p.y) - uint32_t(last->y));
    c.dy.compress(xy, c.lastYDiff[xyIndex].get(), dy, (n == 1) + (kBits < 20 ? (kBits & ~1u) : 20));
    c.lastYDiff[xyIndex].add(dy);

    kBits = (c.dx.getK() + c.dy.getK()) / 2;
    c.z.compress(layers_[kZ].enc, c.lastZ[l], p.z, (n == 1) + (kBits < 18 ? (kBits & ~1u) : 18));
    c.lastZ[l] = p.z;
    layers_[kZ].changed |= p.z != last->z;

    const uint32_t ccc = ((last->classification & 0x1Fu) << 1) + (cpr == 3 ? 1 : 0);
    layers_[kClassification].enc.encodeSymbol(c.classification[ccc], p.classification);
    layers_[kClassification].changed |= p.classification != last->classification;

    const uint32_t lastFlags =
        (last->edgeOfFlightLine << 5) | (last->scanDirection << 4) | last->classificationFlags;
    const uint32_t flags = (p.edgeOfFlightLine << 5) | (p.scanDirection << 4) | p.classificationFlags;
    layers_[kFlags].enc.encodeSymbol(c.flags[lastFlags], flags);
    layers_[kFlags].changed |= flags != lastFlags;

    const uint32_t index = (cpr << 1) | (gpsTimeChange ? 1 : 0);
    c.intensity.compress(layers_[kIntensity].enc, c.lastIntensity[index], p.intensity, cpr);
    c.lastIntensity[index] = p.intensity;
    layers_[kIntensity].changed |= p.intensity != last->intensity;

    if (scanAngleChange) {
      c.scanAngle.compress(layers_[kScanAngle].enc, last->scanAngle, p.scanAngle, gpsTimeChange);
      layers_[kScanAngle].changed = true;
    }
    layers_[kUserData].enc.encodeSymbol(c.userData[last->userData / 4], p.userData);
    layers_[kUserData].changed |= p.userData != last->userData;
    if (pointSourceChange) {
      c.pointSourceId.compress(layers_[kPointSource].enc, last->pointSourceId, p.pointSourceId);
      layers_[kPointSource].changed = true;
    }
    if (gpsTimeChange) {
      writeGpsTime(layers_[kGps].enc, kGpsV3, c.gpsZeroDiff, c.gpsMulti, c.gpsTime, c.gps, p.gpsTime);
      layers_[kGps].changed = true;
    }
    *last = p;
    last->gpsTimeChange = gpsTimeChange;
  }

  // The layers' bytes, in order (the XY layer always, the others only where a value changed).
  void finish(std::vector<std::span<const uint8_t>>& out) {
    for (int i = 0; i < kPoint14Layers; ++i)
      out.push_back(layers_[i].finish(i == kXY || layers_[i].changed));
  }

private:
  // The decoder's context (laz_layered.cpp), one per scanner channel.
  struct Context {
    bool unused = true;
    Point14 last;
    uint16_t lastIntensity[8] = {};
    Median5 lastXDiff[12], lastYDiff[12];
    int32_t lastZ[8] = {};
    SymbolModel changedValues[8];
    SymbolModel scannerChannel{3};
    ContextModels numberOfReturns{16, 16, kEncode}, returnNumber{16, 16, kEncode};
    SymbolModel returnNumberGpsSame{13};
    IntegerCodec dx{32, 2, kEncode}, dy{32, 22, kEncode}, z{32, 20, kEncode};
    ContextModels classification{64, 256, kEncode}, flags{64, 64, kEncode}, userData{64, 256, kEncode};
    IntegerCodec intensity{16, 4, kEncode}, scanAngle{16, 2, kEncode}, pointSourceId{16, 1, kEncode};
    SymbolModel gpsMulti{515, kEncode}, gpsZeroDiff{5};
    IntegerCodec gpsTime{32, 9, kEncode};
    GpsSequences gps;
    Context() {
      for (SymbolModel& m : changedValues)
        m.create(128, kEncode);
    }
  };

  void createContext(uint32_t channel, const Point14& seed) {
    if (!contexts_[channel]) contexts_[channel] = std::make_unique<Context>();
    Context& c = *contexts_[channel];
    for (SymbolModel& m : c.changedValues)
      m.reset();
    c.scannerChannel.reset();
    c.numberOfReturns.invalidate();
    c.returnNumber.invalidate();
    c.returnNumberGpsSame.reset();
    c.dx.reset();
    c.dy.reset();
    c.z.reset();
    c.classification.invalidate();
    c.flags.invalidate();
    c.userData.invalidate();
    c.intensity.reset();
    c.scanAngle.reset();
    c.pointSourceId.reset();
    c.gpsMulti.reset();
    c.gpsZeroDiff.reset();
    c.gpsTime.reset();
    for (int i = 0; i < 12; ++i) {
      c.lastXDiff[i].reset();
      c.lastYDiff[i].reset();
    }
    std::fill(std::begin(c.lastZ), std::end(c.lastZ), seed.z);
    std::fill(std::begin(c.lastIntensity), std::end(c.lastIntensity), seed.intensity);
    c.gps.reset(seed.gpsTime);
    c.last = seed;
    c.last.gpsTimeChange = false;
    c.unused = false;
  }

  std::unique_ptr<Context> contexts_[4];
  uint32_t current_ = 0;
  LayerOut layers_[kPoint14Layers];
};

// RGB14 and RGBNIR14: with the decoder's channel handling (a switch to a channel already seen in the
// chunk keeps predicting from the previous channel's values, see laz_layered.h).
class Rgb14Encoder {
public:
  explicit Rgb14Encoder(bool nir) : nir_(nir) {}

  void init(const uint8_t* item, uint32_t context) {
    for (auto& c : contexts_)
      if (c) c->unused = true;
    rgb_.changed = nirLayer_.changed = false;
    uint16_t seed[4] = {};
    for (int i = 0; i < (nir_ ? 4 : 3); ++i)
      seed[i] = loadLE<uint16_t>(item + 2 * i);
    current_ = context;
    createContext(current_, seed);
  }

  void write(const uint8_t* item, uint32_t context) {
    uint16_t* last = contexts_[current_]->last;
    if (current_ != context) {
      current_ = context;
      if (!contexts_[current_] || contexts_[current_]->unused) {
        createContext(current_, last);
        last = contexts_[current_]->last;
      }
    }
    Context& c = *contexts_[current_];
    uint16_t rgb[3];
    for (int i = 0; i < 3; ++i)
      rgb[i] = loadLE<uint16_t>(item + 2 * i);
    rgb_.changed |= rgb[0] != last[0] || rgb[1] != last[1] || rgb[2] != last[2];
    encodeRgb(rgb_.enc, c.byteUsed, c.diff, last, rgb);
    std::copy(rgb, rgb + 3, last);
    if (!nir_) return;
    const uint16_t v = loadLE<uint16_t>(item + 6);
    const uint32_t sym = ((v & 0xFF) != (last[3] & 0xFF) ? 1 : 0) | ((v >> 8) != (last[3] >> 8) ? 2 : 0);
    nirLayer_.changed |= sym != 0;
    nirLayer_.enc.encodeSymbol(c.nirUsed, sym);
    if (sym & 1) nirLayer_.enc.encodeSymbol(c.nirDiff[0], uint32_t((v & 0xFF) - (last[3] & 0xFF)) & 0xFF);
    if (sym & 2) nirLayer_.enc.encodeSymbol(c.nirDiff[1], uint32_t((v >> 8) - (last[3] >> 8)) & 0xFF);
    last[3] = v;
  }

  void finish(std::vector<std::span<const uint8_t>>& out) {
    out.push_back(rgb_.finish(rgb_.changed));
    if (nir_) out.push_back(nirLayer_.finish(nirLayer_.changed));
  }

private:
  struct Context {
    bool unused = true;
    uint16_t last[4] = {};
    SymbolModel byteUsed{128, kEncode};
    SymbolModel diff[6] = {SymbolModel(256, kEncode), SymbolModel(256, kEncode), SymbolModel(256, kEncode),
                           SymbolModel(256, kEncode), SymbolModel(256, kEncode), SymbolModel(256, kEncode)};
    SymbolModel nirUsed{4};
    SymbolModel nirDiff[2] = {SymbolModel(256, kEncode), SymbolModel(256, kEncode)};
  };

  void createContext(uint32_t channel, const uint16_t* seed) {
    if (!contexts_[channel]) contexts_[channel] = std::make_unique<Context>();
    Context& c = *contexts_[channel];
    c.byteUsed.reset();
    for (SymbolModel& m : c.diff)
      m.reset();
    if (nir_) {
      c.nirUsed.reset();
      c.nirDiff[0].reset();
      c.nirDiff[1].reset();
    }
    std::copy(seed, seed + (nir_ ? 4 : 3), c.last);
    c.unused = false;
  }

  bool nir_;
  std::unique_ptr<Context> contexts_[4];
  uint32_t current_ = 0;
  LayerOut rgb_, nirLayer_;
};

class Byte14Encoder {
public:
  explicit Byte14Encoder(uint32_t count) : count_(count), layers_(count) {}

  void init(const uint8_t* item, uint32_t context) {
    for (auto& c : contexts_)
      if (c) c->unused = true;
    for (LayerOut& l : layers_)
      l.changed = false;
    current_ = context;
    createContext(current_, item);
  }

  void write(const uint8_t* item, uint32_t context) {
    uint8_t* last = contexts_[current_]->last.data();
    if (current_ != context) {
      current_ = context;
      if (!contexts_[current_] || contexts_[current_]->unused) {
        createContext(current_, last);
        last = contexts_[current_]->last.data();
      }
    }
    Context& c = *contexts_[current_];
    for (uint32_t i = 0; i < count_; ++i) {
      layers_[i].enc.encodeSymbol(c.models[i], uint8_t(item[i] - last[i]));
      layers_[i].changed |= item[i] != last[i];
      last[i] = item[i];
    }
  }

  void finish(std::vector<std::span<const uint8_t>>& out) {
    for (LayerOut& l : layers_)
      out.push_back(l.finish(l.changed));
  }

private:
  struct Context {
    bool unused = true;
    std::vector<uint8_t> last;
    ContextModels models;
    explicit Context(uint32_t count) : last(count), models(count, 256, kEncode) {}
  };

  void createContext(uint32_t channel, const uint8_t* seed) {
    if (!contexts_[channel]) contexts_[channel] = std::make_unique<Context>(count_);
    Context& c = *contexts_[channel];
    c.models.invalidate();
    std::memcpy(c.last.data(), seed, count_);
    c.unused = false;
  }

  uint32_t count_;
  std::unique_ptr<Context> contexts_[4];
  uint32_t current_ = 0;
  std::vector<LayerOut> layers_;
};

// The first record raw, the point count (u32), every layer's byte size (u32), then the layers.
class LayeredChunkEncoder {
public:
  explicit LayeredChunkEncoder(const Layout& layout) : recordLength_(layout.recordLength) {
    size_t offset = 0;
    for (const Item& item : layout.items) {
      if (item.type == ItemType::Rgb14 || item.type == ItemType::RgbNir14) {
        rgb_ = std::make_unique<Rgb14Encoder>(item.type == ItemType::RgbNir14);
        rgbOffset_ = offset;
      } else if (item.type == ItemType::Byte14) {
        bytes_ = std::make_unique<Byte14Encoder>(item.size);
        bytesOffset_ = offset;
      }
      offset += item.size;
    }
  }

  std::vector<uint8_t> encode(const uint8_t* records, uint64_t count) {
    const size_t rl = recordLength_;
    uint32_t context = 0;
    point_.init(records, context);
    if (rgb_) rgb_->init(records + rgbOffset_, context);
    if (bytes_) bytes_->init(records + bytesOffset_, context);
    for (uint64_t i = 1; i < count; ++i) {
      const uint8_t* record = records + i * rl;
      context = 0; // as the decoder: the channel reaches the other items only at a switch
      point_.write(record, context);
      if (rgb_) rgb_->write(record + rgbOffset_, context);
      if (bytes_) bytes_->write(record + bytesOffset_, context);
    }
    std::vector<std::span<const uint8_t>>& layers = layers_;
    layers.clear();
    point_.finish(layers);
    if (rgb_) rgb_->finish(layers);
    if (bytes_) bytes_->finish(layers);
    size_t total = 0;
    for (const auto& l : layers)
      total += l.size();
    std::vector<uint8_t> out(rl + 4 + 4 * layers.size() + total);
    std::memcpy(out.data(), records, rl);
    storeLE<uint32_t>(out.data() + rl, uint32_t(count));
    size_t at = rl + 4 + 4 * layers.size();
    for (size_t i = 0; i < layers.size(); ++i) {
      storeLE<uint32_t>(out.data() + rl + 4 + 4 * i, uint32_t(layers[i].size()));
      if (!layers[i].empty()) std::memcpy(out.data() + at, layers[i].data(), layers[i].size());
      at += layers[i].size();
    }
    return out;
  }

private:
  size_t recordLength_;
  Point14Encoder point_;
  std::unique_ptr<Rgb14Encoder> rgb_;
  std::unique_ptr<Byte14Encoder> bytes_;
  size_t rgbOffset_ = 0, bytesOffset_ = 0;
  std::vector<std::span<const uint8_t>> layers_; // the last chunk's layers, in their coders' buffers
};

// ---- the chunk, the layout, the VLR ---------------------------------------------------------------------

ChunkEncoder::ChunkEncoder(const Layout& layout) : layout_(layout) {
  if (layout.layered())
    layered_ = std::make_unique<LayeredChunkEncoder>(layout);
  else
    pointwise_ = std::make_unique<PointwiseChunkEncoder>(layout);
}

ChunkEncoder::~ChunkEncoder() = default;

std::vector<uint8_t> ChunkEncoder::encode(const uint8_t* records, uint64_t count) {
  // A layered chunk states its count in 32 bits; LASzip's chunks hold far fewer points.
  assert(count >= 1 && count <= UINT32_MAX);
  return layered_ ? layered_->encode(records, count) : pointwise_->encode(records, count);
}

bool canEncodePointFormat(int pointFormat) {
  return (pointFormat >= 0 && pointFormat <= 3) || (pointFormat >= 6 && pointFormat <= 8);
}

Layout encoderLayout(int pointFormat, uint16_t recordLength, uint32_t chunkSize) {
  Layout layout;
  layout.chunkSize = chunkSize;
  layout.recordLength = recordLength;
  const bool layered = pointFormat >= 6;
  layout.compressor = layered ? Compressor::LayeredChunked : Compressor::PointwiseChunked;
  // The LASzip release whose items these are: 2.2 for pointwise chunks, 3.4 r3 for layered ones.
  layout.versionMajor = layered ? 3 : 2;
  layout.versionMinor = layered ? 4 : 2;
  layout.versionRevision = layered ? 3 : 0;
  const uint16_t version = layered ? 3 : 2;
  auto add = [&](ItemType type, uint16_t size) { layout.items.push_back({type, size, version}); };
  uint16_t size = 0;
  if (layered) {
    add(ItemType::Point14, 30);
    size = 30;
    if (pointFormat == 7) add(ItemType::Rgb14, 6), size += 6;
    if (pointFormat == 8) add(ItemType::RgbNir14, 8), size += 8;
  } else {
    add(ItemType::Point10, 20);
    size = 20;
    if (pointFormat == 1 || pointFormat == 3) add(ItemType::GpsTime11, 8), size += 8;
    if (pointFormat == 2 || pointFormat == 3) add(ItemType::Rgb12, 6), size += 6;
  }
  if (recordLength > size) add(layered ? ItemType::Byte14 : ItemType::Byte, uint16_t(recordLength - size));
  return layout;
}

std::vector<uint8_t> laszipVlrPayload(const Layout& layout) {
  // Compressor u16, coder u16 (0: arithmetic), LASzip version u8 u8 u16, options u32, chunk size u32,
  // special EVLR count i64 and offset i64 (-1: none), item count u16, then type, size, version (u16 each).
  std::vector<uint8_t> out(34 + 6 * layout.items.size());
  uint8_t* p = out.data();
  storeLE<uint16_t>(p, uint16_t(layout.compressor));
  storeLE<uint16_t>(p + 2, 0);
  p[4] = layout.versionMajor;
  p[5] = layout.versionMinor;
  storeLE<uint16_t>(p + 6, layout.versionRevision);
  storeLE<uint32_t>(p + 8, 0);
  storeLE<uint32_t>(p + 12, layout.chunkSize);
  storeLE<int64_t>(p + 16, -1);
  storeLE<int64_t>(p + 24, -1);
  storeLE<uint16_t>(p + 32, uint16_t(layout.items.size()));
  for (size_t i = 0; i < layout.items.size(); ++i) {
    storeLE<uint16_t>(p + 34 + 6 * i, uint16_t(layout.items[i].type));
    storeLE<uint16_t>(p + 36 + 6 * i, layout.items[i].size);
    storeLE<uint16_t>(p + 38 + 6 * i, layout.items[i].version);
  }
  return out;
}

std::vector<std::vector<uint8_t>> encodeChunks(const Layout& layout, const uint8_t* records,
                                               const std::vector<uint64_t>& counts, unsigned threads) {
  std::vector<uint64_t> first(counts.size());
  uint64_t at = 0;
  for (size_t i = 0; i < counts.size(); ++i) {
    first[i] = at;
    at += counts[i];
  }
  std::vector<std::vector<uint8_t>> out(counts.size());
  std::mutex mutex;
  std::vector<std::unique_ptr<ChunkEncoder>> idle;
  parallelBlocksOn(threads, counts.size(), 1, [&](uint64_t i, uint64_t, uint64_t) {
    std::unique_ptr<ChunkEncoder> encoder;
    {
      std::lock_guard lock(mutex);
      if (!idle.empty()) {
        encoder = std::move(idle.back());
        idle.pop_back();
      }
    }
    if (!encoder) encoder = std::make_unique<ChunkEncoder>(layout);
    out[i] = encoder->encode(records + first[i] * layout.recordLength, counts[i]);
    std::lock_guard lock(mutex);
    idle.push_back(std::move(encoder));
  });
  return out;
}

} // namespace pointrast::io::laz
