// Writing LAZ: the encoders that mirror the item decoders (laz_pointwise.h, laz_layered.h). Every model,
// context and prediction is the decoder's, updated in the same order, so the decoder's models adapt
// exactly as the encoder's did and decode the records byte for byte.
//
// An encoder chooses how to code a value (which multiplier of a GPS time difference, which sequence);
// the choices here are valid codes for any decoder of the format (LASzip, laz-perf, laz-rs, pointrast's),
// not necessarily the bytes LASzip writes.
//
// Point formats 0-3 are coded pointwise with version 2 items (POINT10, GPSTIME11, RGB12, BYTE), formats
// 6-8 layered with version 3 items (POINT14, RGB14, RGBNIR14, BYTE14), each with its extra bytes.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "io/las/laz_format.h"

namespace pointrast::io::laz {

// Whether records of this point format can be written as LAZ (0-3, 6-8).
bool canEncodePointFormat(int pointFormat);

// The items for records of `pointFormat` (0-3, 6-8) and `recordLength` bytes (the format's size plus
// extra bytes), coded in chunks of `chunkSize` points (kVariableChunks: each chunk its own count).
Layout encoderLayout(int pointFormat, uint16_t recordLength, uint32_t chunkSize);

// The payload of the LASzip VLR ("laszip encoded", 22204) describing `layout`.
std::vector<uint8_t> laszipVlrPayload(const Layout& layout);

class PointwiseChunkEncoder;
class LayeredChunkEncoder;

// Encodes chunks of raw LAS records. Owns the item models; one per thread, reused from chunk to chunk.
class ChunkEncoder {
public:
  explicit ChunkEncoder(const Layout& layout);
  ~ChunkEncoder();
  ChunkEncoder(const ChunkEncoder&) = delete;
  ChunkEncoder& operator=(const ChunkEncoder&) = delete;

  // The bytes of one chunk holding `count` records (count >= 1) of layout.recordLength bytes each.
  std::vector<uint8_t> encode(const uint8_t* records, uint64_t count);

private:
  Layout layout_;
  std::unique_ptr<PointwiseChunkEncoder> pointwise_;
  std::unique_ptr<LayeredChunkEncoder> layered_;
};

// Encodes chunks of the records [0, sum of counts) on all cores (`threads`, 0 for all hardware
// threads): chunk i holds counts[i] records following chunk i - 1's. Returns each chunk's bytes.
std::vector<std::vector<uint8_t>> encodeChunks(const Layout& layout, const uint8_t* records,
                                               const std::vector<uint64_t>& counts, unsigned threads = 0);

} // namespace pointrast::io::laz
