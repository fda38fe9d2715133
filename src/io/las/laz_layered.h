// LASzip's layered item decoders, version 3 (LAS 1.4 point formats 6-10): within a chunk every
// attribute is its own arithmetic-coded layer (XY with returns and scanner channel, Z, classification,
// flags, intensity, scan angle, user data, point source id, GPS time, RGB, NIR, each extra byte), and
// each of the four scanner channels keeps its own prediction context.
//
// LASzip's behaviour is reproduced where files depend on it: when the scanner channel switches to a
// channel already seen in the chunk, the RGB, NIR and extra-byte decoders keep predicting from the
// previous channel's last values (with the new channel's models) and store the result there; and those
// decoders are handed the new channel only at the point that switches, channel 0 at every other point
// (LASzip's per-point context starts at 0 in version 3). Those are LASzip quirks, but every
// LASzip-written file with several channels encodes exactly that, and laz-perf and laz-rs decode it so.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "io/las/laz_arithmetic.h"
#include "io/las/laz_common.h"
#include "io/las/laz_format.h"
#include "io/las/laz_integer.h"
#include "io/las/laz_pointwise.h"

namespace pointrast::io::laz {

// The bytes of one layer inside a chunk.
struct Layer {
  const uint8_t* data = nullptr;
  uint32_t size = 0;
};

// The attributes of a point-format-6 record that POINT14 codes (LASzip's LASpoint14 as far as the coder
// reads it), plus whether the GPS time changed at this point (a context for the next one).
struct Point14 {
  int32_t x = 0, y = 0, z = 0;
  uint16_t intensity = 0;
  uint8_t returnNumber = 0, numberOfReturns = 0;
  uint8_t classificationFlags = 0, scannerChannel = 0, scanDirection = 0, edgeOfFlightLine = 0;
  uint8_t classification = 0, userData = 0;
  int16_t scanAngle = 0;
  uint16_t pointSourceId = 0;
  uint64_t gpsTime = 0; // the double's bits
  bool gpsTimeChange = false;

  static Point14 parse(const uint8_t* raw);
  void write(uint8_t* raw) const;
};

class Point14Decoder {
public:
  static constexpr int kLayers = 9; // XY + returns + channel, Z, classification, flags, intensity,
                                    // scan angle, user data, point source id, GPS time
  Point14Decoder();
  ~Point14Decoder();
  // Start of a chunk: the raw first point, this chunk's layers. Sets context (the scanner channel) for
  // the other items.
  void init(const uint8_t* item, const Layer* layers, uint32_t& context);
  void read(uint8_t* item, uint32_t& context);
  // Largest count of bytes a used layer decoder read past its end.
  size_t pastEnd() const;

private:
  struct Context;
  void createContext(uint32_t channel, const Point14& seed);
  void readGpsTime(Context& c);

  std::unique_ptr<Context> contexts_[4];
  uint32_t current_ = 0;
  ArithmeticDecoder dec_[kLayers];
  bool changed_[kLayers] = {};
};

// RGB14 (6 B) and RGBNIR14 (8 B): the RGB layer codes like RGB12; NIR is its own layer, two bytes.
class Rgb14Decoder {
public:
  explicit Rgb14Decoder(bool nir);
  ~Rgb14Decoder();
  int layerCount() const { return nir_ ? 2 : 1; }
  void init(const uint8_t* item, const Layer* layers, uint32_t context);
  void read(uint8_t* item, uint32_t context);
  size_t pastEnd() const;

private:
  struct Context;
  void createContext(uint32_t channel, const uint16_t* seed);

  bool nir_;
  std::unique_ptr<Context> contexts_[4];
  uint32_t current_ = 0;
  ArithmeticDecoder rgb_, nirDec_;
  bool changedRgb_ = false, changedNir_ = false;
};

// BYTE14: every extra byte is its own layer.
class Byte14Decoder {
public:
  explicit Byte14Decoder(uint32_t count);
  ~Byte14Decoder();
  int layerCount() const { return int(count_); }
  void init(const uint8_t* item, const Layer* layers, uint32_t context);
  void read(uint8_t* item, uint32_t context);
  size_t pastEnd() const;

private:
  struct Context;
  void createContext(uint32_t channel, const uint8_t* seed);

  uint32_t count_;
  std::unique_ptr<Context> contexts_[4];
  uint32_t current_ = 0;
  std::vector<ArithmeticDecoder> dec_;
  std::vector<uint8_t> changed_;
};

// A layered chunk: the first point raw, the point count (u32), the byte size of every layer (u32 each:
// POINT14's nine, then RGB and NIR, then one per extra byte), then the layers in that order.
class LayeredChunkDecoder {
public:
  explicit LayeredChunkDecoder(const Layout& layout);
  ~LayeredChunkDecoder();
  // out: count raw records (see ChunkDecoder::decode). Throws CorruptChunk.
  void decode(const uint8_t* data, size_t size, uint64_t count, std::vector<uint8_t>& out);

private:
  void readLayers(const uint8_t* data, size_t size, uint64_t count);
  size_t pastEnd() const;

  size_t recordLength_;
  Point14Decoder point_;
  std::unique_ptr<Rgb14Decoder> rgb_;
  std::unique_ptr<Byte14Decoder> bytes_;
  size_t rgbOffset_ = 0, bytesOffset_ = 0;
  std::vector<Layer> layers_;
};

} // namespace pointrast::io::laz
