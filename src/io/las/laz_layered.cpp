#include "io/las/laz_layered.h"

#include <algorithm>
#include <cstring>

#include "io/io_util.h"

namespace pointrast::io::laz {

using detail::loadLE;
using detail::storeLE;

// ---- Point14 ------------------------------------------------------------------------------------------
// Record layout (LAS 1.4 R15, point format 6): X, Y, Z int32 at 0, 4, 8; intensity at 12; byte 14:
// return number (bits 0-3), number of returns (4-7); byte 15: classification flags (0-3), scanner
// channel (4-5), scan direction (6), edge of flight line (7); classification at 16; user data at 17;
// scan angle int16 at 18; point source id at 20; GPS time double at 22.

Point14 Point14::parse(const uint8_t* raw) {
  Point14 p;
  p.x = loadLE<int32_t>(raw);
  p.y = loadLE<int32_t>(raw + 4);
  p.z = loadLE<int32_t>(raw + 8);
  p.intensity = loadLE<uint16_t>(raw + 12);
  p.returnNumber = raw[14] & 15;
  p.numberOfReturns = raw[14] >> 4;
  p.classificationFlags = raw[15] & 15;
  p.scannerChannel = (raw[15] >> 4) & 3;
  p.scanDirection = (raw[15] >> 6) & 1;
  p.edgeOfFlightLine = raw[15] >> 7;
  p.classification = raw[16];
  p.userData = raw[17];
  p.scanAngle = loadLE<int16_t>(raw + 18);
  p.pointSourceId = loadLE<uint16_t>(raw + 20);
  p.gpsTime = loadLE<uint64_t>(raw + 22);
  return p;
}

void Point14::write(uint8_t* raw) const {
  storeLE<int32_t>(raw, x);
  storeLE<int32_t>(raw + 4, y);
  storeLE<int32_t>(raw + 8, z);
  storeLE<uint16_t>(raw + 12, intensity);
  raw[14] = static_cast<uint8_t>(returnNumber | (numberOfReturns << 4));
  raw[15] = static_cast<uint8_t>(classificationFlags | (scannerChannel << 4) | (scanDirection << 6) |
                                 (edgeOfFlightLine << 7));
  raw[16] = classification;
  raw[17] = userData;
  storeLE<int16_t>(raw + 18, scanAngle);
  storeLE<uint16_t>(raw + 20, pointSourceId);
  storeLE<uint64_t>(raw + 22, gpsTime);
}

// ---- POINT14 v3 ---------------------------------------------------------------------------------------

namespace {
enum Point14Layer { kXY, kZ, kClassification, kFlags, kIntensity, kScanAngle, kUserData, kPointSource, kGps };
// GPS time after a zero difference (5 symbols): 0 a new difference, 1 a full time, 2..4 a switch to
// sequence last + 1..3. Otherwise (515 symbols): the shared multipliers 0..510, 511 a full time,
// 512..514 a switch. There is no "unchanged" symbol: the XY layer says whether the time changed.
constexpr uint32_t kGps3CodeFull = 511;
constexpr uint32_t kGps3Symbols = 515;
} // namespace

struct Point14Decoder::Context {
  bool unused = true;
  Point14 last;
  uint16_t lastIntensity[8] = {};
  Median5 lastXDiff[12], lastYDiff[12];
  int32_t lastZ[8] = {};

  SymbolModel changedValues[8]; // by the last point's return position and GPS change
  SymbolModel scannerChannel{3};
  ContextModels numberOfReturns{16, 16}, returnNumber{16, 16};
  SymbolModel returnNumberGpsSame{13};
  IntegerCodec dx{32, 2}, dy{32, 22}, z{32, 20};
  ContextModels classification{64, 256}, flags{64, 64}, userData{64, 256};
  IntegerCodec intensity{16, 4}, scanAngle{16, 2}, pointSourceId{16, 1};
  SymbolModel gpsMulti{kGps3Symbols}, gpsZeroDiff{5};
  IntegerCodec gpsTime{32, 9};
  GpsSequences gps;

  Context() {
    for (SymbolModel& m : changedValues)
      m.create(128);
  }
};

Point14Decoder::Point14Decoder() = default;
Point14Decoder::~Point14Decoder() = default;

void Point14Decoder::createContext(uint32_t channel, const Point14& seed) {
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
  // Unlike version 2, the first point's Z and intensity seed the predictions.
  std::fill(std::begin(c.lastZ), std::end(c.lastZ), seed.z);
  std::fill(std::begin(c.lastIntensity), std::end(c.lastIntensity), seed.intensity);
  c.gps.reset(seed.gpsTime);
  c.last = seed;
  c.last.gpsTimeChange = false;
  c.unused = false;
}

void Point14Decoder::init(const uint8_t* item, const Layer* layers, uint32_t& context) {
  for (int i = 0; i < kLayers; ++i) {
    changed_[i] = i == kXY || layers[i].size > 0;
    if (changed_[i]) dec_[i].init(layers[i].data, layers[i].data + layers[i].size);
  }
  for (auto& c : contexts_)
    if (c) c->unused = true;
  const Point14 first = Point14::parse(item);
  current_ = first.scannerChannel;
  context = current_;
  createContext(current_, first);
}

size_t Point14Decoder::pastEnd() const {
  size_t worst = 0;
  for (int i = 0; i < kLayers; ++i)
    if (changed_[i]) worst = std::max(worst, dec_[i].pastEnd());
  return worst;
}

[[gnu::always_inline]] inline void Point14Decoder::read(uint8_t* item, uint32_t& context) {
  // The coordinate layer's coder as a local for the point's symbols (up to a dozen), so that its state
  // stays in registers between them rather than in this decoder's memory; stored back after Y.
  ArithmeticDecoder xy = dec_[kXY];
  Point14* last = &contexts_[current_]->last;

  // The changed-values symbol, in the context of the last point's return position (bit 0: first,
  // bit 1: last) and whether its GPS time changed. Bits: 6 scanner channel, 5 point source id, 4 GPS
  // time, 3 scan angle, 2 number of returns, 0-1 return number (same, +1, -1, coded).
  const uint32_t lpr = (last->returnNumber == 1 ? 1 : 0) +
                       (last->returnNumber >= last->numberOfReturns ? 2 : 0) + (last->gpsTimeChange ? 4 : 0);
  const uint32_t changed = xy.decodeSymbol(contexts_[current_]->changedValues[lpr]);
  if (changed & (1 << 6)) {
    const uint32_t channel = (current_ + xy.decodeSymbol(contexts_[current_]->scannerChannel) + 1) % 4;
    if (!contexts_[channel] || contexts_[channel]->unused) createContext(channel, *last);
    current_ = channel;
    context = channel;
    last = &contexts_[current_]->last;
    last->scannerChannel = static_cast<uint8_t>(channel);
  }
  Context& c = *contexts_[current_];
  const bool pointSourceChange = changed & (1 << 5);
  const bool gpsTimeChange = changed & (1 << 4);
  const bool scanAngleChange = changed & (1 << 3);

  uint32_t n = last->numberOfReturns;
  if (changed & (1 << 2)) {
    n = xy.decodeSymbol(c.numberOfReturns[n]);
    last->numberOfReturns = static_cast<uint8_t>(n);
  }
  uint32_t r = last->returnNumber;
  switch (changed & 3) {
  case 0:
    break;
  case 1:
    r = (r + 1) % 16;
    break;
  case 2:
    r = (r + 15) % 16;
    break;
  default:
    if (gpsTimeChange)
      r = xy.decodeSymbol(c.returnNumber[r]);
    else
      r = (r + xy.decodeSymbol(c.returnNumberGpsSame) + 2) % 16;
    break;
  }
  last->returnNumber = static_cast<uint8_t>(r);

  const uint32_t m = kReturnMap6[n][r];
  const uint32_t l = returnLevel(n, r);
  const uint32_t cpr = (r == 1 ? 1 : 0) + (r >= n ? 2 : 0);
  const uint32_t xyIndex = (m << 1) | (gpsTimeChange ? 1 : 0);

  const int32_t dx = c.dx.decompress(xy, c.lastXDiff[xyIndex].get(), n == 1);
  last->x = addWrap(last->x, dx);
  c.lastXDiff[xyIndex].add(dx);
  uint32_t kBits = c.dx.getK();
  const int32_t dy =
      c.dy.decompress(xy, c.lastYDiff[xyIndex].get(), (n == 1) + (kBits < 20 ? (kBits & ~1u) : 20));
  last->y = addWrap(last->y, dy);
  c.lastYDiff[xyIndex].add(dy);
  dec_[kXY] = xy;

  if (changed_[kZ]) {
    kBits = (c.dx.getK() + c.dy.getK()) / 2;
    last->z = c.z.decompress(dec_[kZ], c.lastZ[l], (n == 1) + (kBits < 18 ? (kBits & ~1u) : 18));
    c.lastZ[l] = last->z;
  }
  if (changed_[kClassification]) {
    const uint32_t ccc = ((last->classification & 0x1Fu) << 1) + (cpr == 3 ? 1 : 0);
    last->classification = static_cast<uint8_t>(dec_[kClassification].decodeSymbol(c.classification[ccc]));
  }
  if (changed_[kFlags]) {
    const uint32_t lastFlags =
        (last->edgeOfFlightLine << 5) | (last->scanDirection << 4) | last->classificationFlags;
    const uint32_t flags = dec_[kFlags].decodeSymbol(c.flags[lastFlags]);
    last->edgeOfFlightLine = (flags >> 5) & 1;
    last->scanDirection = (flags >> 4) & 1;
    last->classificationFlags = flags & 15;
  }
  if (changed_[kIntensity]) {
    const uint32_t index = (cpr << 1) | (gpsTimeChange ? 1 : 0);
    const auto intensity =
        static_cast<uint16_t>(c.intensity.decompress(dec_[kIntensity], c.lastIntensity[index], cpr));
    c.lastIntensity[index] = intensity;
    last->intensity = intensity;
  }
  if (changed_[kScanAngle] && scanAngleChange)
    last->scanAngle =
        static_cast<int16_t>(c.scanAngle.decompress(dec_[kScanAngle], last->scanAngle, gpsTimeChange));
  if (changed_[kUserData])
    last->userData = static_cast<uint8_t>(dec_[kUserData].decodeSymbol(c.userData[last->userData / 4]));
  if (changed_[kPointSource] && pointSourceChange)
    last->pointSourceId =
        static_cast<uint16_t>(c.pointSourceId.decompress(dec_[kPointSource], last->pointSourceId));
  if (changed_[kGps] && gpsTimeChange) {
    readGpsTime(c);
    last->gpsTime = c.gps.current();
  }
  last->write(item);
  last->gpsTimeChange = gpsTimeChange;
}

[[gnu::always_inline]] inline void Point14Decoder::readGpsTime(Context& c) {
  ArithmeticDecoder& dec = dec_[kGps];
  GpsSequences& seq = c.gps;
  for (int hop = 0;; ++hop) {
    if (hop > kMaxSequenceHops) corrupt("its GPS times switch sequences without end");
    if (seq.diff[seq.last] == 0) {
      const uint32_t multi = dec.decodeSymbol(c.gpsZeroDiff);
      if (multi == 0) {
        seq.readFirstDiff(dec, c.gpsTime);
      } else if (multi == 1) {
        seq.readFull(dec, c.gpsTime);
      } else {
        seq.last = (seq.last + multi - 1) & 3;
        continue;
      }
    } else {
      const uint32_t multi = dec.decodeSymbol(c.gpsMulti);
      if (multi == 1) {
        seq.readSameDiff(dec, c.gpsTime);
      } else if (multi < kGps3CodeFull) {
        seq.readMultiple(dec, c.gpsTime, multi);
      } else if (multi == kGps3CodeFull) {
        seq.readFull(dec, c.gpsTime);
      } else {
        seq.last = (seq.last + multi - kGps3CodeFull) & 3;
        continue;
      }
    }
    return;
  }
}

// ---- RGB14 / RGBNIR14 v3 ------------------------------------------------------------------------------

struct Rgb14Decoder::Context {
  bool unused = true;
  uint16_t last[4] = {};
  SymbolModel byteUsed{128};
  SymbolModel diff[6] = {SymbolModel(256), SymbolModel(256), SymbolModel(256),
                         SymbolModel(256), SymbolModel(256), SymbolModel(256)};
  SymbolModel nirUsed{4};
  SymbolModel nirDiff[2] = {SymbolModel(256), SymbolModel(256)};
};

Rgb14Decoder::Rgb14Decoder(bool nir) : nir_(nir) {}
Rgb14Decoder::~Rgb14Decoder() = default;

void Rgb14Decoder::createContext(uint32_t channel, const uint16_t* seed) {
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

void Rgb14Decoder::init(const uint8_t* item, const Layer* layers, uint32_t context) {
  changedRgb_ = layers[0].size > 0;
  if (changedRgb_) rgb_.init(layers[0].data, layers[0].data + layers[0].size);
  changedNir_ = nir_ && layers[1].size > 0;
  if (changedNir_) nirDec_.init(layers[1].data, layers[1].data + layers[1].size);
  for (auto& c : contexts_)
    if (c) c->unused = true;
  uint16_t seed[4] = {};
  for (int i = 0; i < (nir_ ? 4 : 3); ++i)
    seed[i] = loadLE<uint16_t>(item + 2 * i);
  current_ = context;
  createContext(current_, seed);
}

size_t Rgb14Decoder::pastEnd() const {
  return std::max(changedRgb_ ? rgb_.pastEnd() : 0, changedNir_ ? nirDec_.pastEnd() : 0);
}

[[gnu::always_inline]] inline void Rgb14Decoder::read(uint8_t* item, uint32_t context) {
  uint16_t* last = contexts_[current_]->last;
  if (current_ != context) {
    current_ = context;
    // LASzip switches to the new channel's last values only when the channel is new in this chunk.
    if (!contexts_[current_] || contexts_[current_]->unused) {
      createContext(current_, last);
      last = contexts_[current_]->last;
    }
  }
  Context& c = *contexts_[current_];
  if (changedRgb_) {
    uint16_t rgb[3];
    decodeRgb(rgb_, c.byteUsed, c.diff, last, rgb);
    std::copy(rgb, rgb + 3, last);
  }
  for (int i = 0; i < 3; ++i)
    storeLE<uint16_t>(item + 2 * i, last[i]);
  if (!nir_) return;
  if (changedNir_) {
    const uint32_t sym = nirDec_.decodeSymbol(c.nirUsed);
    uint32_t v =
        sym & 1 ? foldByte(int32_t(nirDec_.decodeSymbol(c.nirDiff[0])) + (last[3] & 0xFF)) : last[3] & 0xFFu;
    v |= sym & 2 ? uint32_t(foldByte(int32_t(nirDec_.decodeSymbol(c.nirDiff[1])) + (last[3] >> 8))) << 8
                 : last[3] & 0xFF00u;
    last[3] = static_cast<uint16_t>(v);
  }
  storeLE<uint16_t>(item + 6, last[3]);
}

// ---- BYTE14 v3 ----------------------------------------------------------------------------------------

struct Byte14Decoder::Context {
  bool unused = true;
  std::vector<uint8_t> last;
  ContextModels models; // one per byte, created at first use
  explicit Context(uint32_t count) : last(count), models(count, 256) {}
};

Byte14Decoder::Byte14Decoder(uint32_t count) : count_(count), dec_(count), changed_(count) {}
Byte14Decoder::~Byte14Decoder() = default;

void Byte14Decoder::createContext(uint32_t channel, const uint8_t* seed) {
  if (!contexts_[channel]) contexts_[channel] = std::make_unique<Context>(count_);
  Context& c = *contexts_[channel];
  c.models.invalidate();
  std::memcpy(c.last.data(), seed, count_);
  c.unused = false;
}

void Byte14Decoder::init(const uint8_t* item, const Layer* layers, uint32_t context) {
  for (uint32_t i = 0; i < count_; ++i) {
    changed_[i] = layers[i].size > 0;
    if (changed_[i]) dec_[i].init(layers[i].data, layers[i].data + layers[i].size);
  }
  for (auto& c : contexts_)
    if (c) c->unused = true;
  current_ = context;
  createContext(current_, item);
}

size_t Byte14Decoder::pastEnd() const {
  size_t worst = 0;
  for (uint32_t i = 0; i < count_; ++i)
    if (changed_[i]) worst = std::max(worst, dec_[i].pastEnd());
  return worst;
}

[[gnu::always_inline]] inline void Byte14Decoder::read(uint8_t* item, uint32_t context) {
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
    if (changed_[i]) last[i] = foldByte(int32_t(last[i]) + int32_t(dec_[i].decodeSymbol(c.models[i])));
    item[i] = last[i];
  }
}

// ---- the chunk ----------------------------------------------------------------------------------------

LayeredChunkDecoder::LayeredChunkDecoder(const Layout& layout) : recordLength_(layout.recordLength) {
  size_t offset = 0;
  for (const Item& item : layout.items) {
    // parseLaszipVlr admits these items in this order only.
    if (item.type == ItemType::Rgb14 || item.type == ItemType::RgbNir14) {
      rgb_ = std::make_unique<Rgb14Decoder>(item.type == ItemType::RgbNir14);
      rgbOffset_ = offset;
    } else if (item.type == ItemType::Byte14) {
      bytes_ = std::make_unique<Byte14Decoder>(item.size);
      bytesOffset_ = offset;
    }
    offset += item.size;
  }
  layers_.resize(Point14Decoder::kLayers + (rgb_ ? rgb_->layerCount() : 0) +
                 (bytes_ ? bytes_->layerCount() : 0));
}

LayeredChunkDecoder::~LayeredChunkDecoder() = default;

void LayeredChunkDecoder::readLayers(const uint8_t* data, size_t size, uint64_t count) {
  const size_t header = recordLength_ + 4 + 4 * layers_.size();
  if (size < header) corrupt("its data ends inside the layer table");
  const uint32_t chunkCount = loadLE<uint32_t>(data + recordLength_);
  if (chunkCount != count)
    corrupt(detail::strFormat("it counts %u points itself, the file's index %llu", chunkCount,
                              static_cast<unsigned long long>(count))
                .c_str());
  size_t offset = header;
  for (size_t i = 0; i < layers_.size(); ++i) {
    const uint32_t bytesInLayer = loadLE<uint32_t>(data + recordLength_ + 4 + 4 * i);
    if (bytesInLayer > size - offset) corrupt("its layers run past its end");
    layers_[i] = {data + offset, bytesInLayer};
    offset += bytesInLayer;
  }
}

size_t LayeredChunkDecoder::pastEnd() const {
  return std::max({point_.pastEnd(), rgb_ ? rgb_->pastEnd() : 0, bytes_ ? bytes_->pastEnd() : 0});
}

void LayeredChunkDecoder::decode(const uint8_t* data, size_t size, uint64_t count,
                                 std::vector<uint8_t>& out) {
  const size_t rl = recordLength_;
  if (size < rl) corrupt("its data ends inside the first point");
  readLayers(data, size, count);
  if (count > 1 && layers_[0].size == 0) corrupt("its coordinate layer is empty");
  uint64_t capacity = initialRecordCapacity(count, size);
  out.resize(capacity * rl);
  std::memcpy(out.data(), data, rl);
  uint32_t context = 0;
  point_.init(data, layers_.data(), context);
  size_t next = Point14Decoder::kLayers;
  if (rgb_) {
    rgb_->init(data + rgbOffset_, layers_.data() + next, context);
    next += size_t(rgb_->layerCount());
  }
  if (bytes_) bytes_->init(data + bytesOffset_, layers_.data() + next, context);
  for (uint64_t i = 1; i < count; ++i) {
    uint8_t* record = recordSlot(out, i, capacity, rl, count);
    // LASzip's version 3 items hand the other items channel 0 unless the point switches channels (its
    // per-point context starts at 0 and POINT14 sets it only on a switch); LASzip, laz-perf and laz-rs
    // all code RGB, NIR and extra bytes of multi-channel files that way.
    context = 0;
    point_.read(record, context);
    if (rgb_) rgb_->read(record + rgbOffset_, context);
    if (bytes_) bytes_->read(record + bytesOffset_, context);
    // The coordinate layer advances with every point; the others are checked once at the end.
    if (point_.pastEnd() > kPastEndSlack) corrupt("its data ends before its last point");
  }
  if (count > 1 && pastEnd() > kPastEndSlack) corrupt("one of its layers ends before its last point");
}

} // namespace pointrast::io::laz
