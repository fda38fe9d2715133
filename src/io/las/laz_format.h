// The LAZ container (LASzip): a LAS file whose point records are replaced by compressed chunks. The
// "laszip encoded" VLR (record 22204) says how the records are coded (the items and their versions,
// pointwise or layered, the chunk size); the point data begins with the 64-bit offset of the chunk
// table, then the chunks, each decodable on its own; the chunk table (arithmetic coded) gives each
// chunk's byte size and, for variable chunks, its point count.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/las/las_format.h"

namespace pointrast::io::laz {

// Item types of the LASzip VLR.
enum class ItemType : uint16_t {
  Byte = 0,
  Point10 = 6,
  GpsTime11 = 7,
  Rgb12 = 8,
  WavePacket13 = 9,
  Point14 = 10,
  Rgb14 = 11,
  RgbNir14 = 12,
  WavePacket14 = 13,
  Byte14 = 14,
};
const char* itemName(ItemType type);

struct Item {
  ItemType type = ItemType::Byte;
  uint16_t size = 0;
  uint16_t version = 0;
};

enum class Compressor : uint16_t { None = 0, Pointwise = 1, PointwiseChunked = 2, LayeredChunked = 3 };

inline constexpr uint32_t kVariableChunks = 0xFFFFFFFFu;

// How a file's points are coded, from its LASzip VLR, checked against the header.
struct Layout {
  Compressor compressor = Compressor::PointwiseChunked;
  uint32_t chunkSize = 50000; // points per chunk, or kVariableChunks (the table gives each count)
  std::vector<Item> items;
  uint16_t recordLength = 0;
  uint8_t versionMajor = 0, versionMinor = 0; // of the LASzip that wrote the file
  uint16_t versionRevision = 0;

  bool layered() const { return compressor == Compressor::LayeredChunked; }
  bool variableChunks() const { return chunkSize == kVariableChunks; }
  // "POINT10 v2, GPSTIME11 v2, RGB12 v2" (extra bytes with their count).
  std::string describeItems() const;
  // "layered chunks", "pointwise chunks"...
  std::string describeCompressor() const;
};

// One chunk: where its bytes are and which points it holds.
struct Chunk {
  uint64_t offset = 0;
  uint64_t bytes = 0;
  uint64_t firstPoint = 0;
  uint64_t pointCount = 0;
};

struct LazFile {
  detail::LasHeader header;
  Layout layout;
  std::vector<Chunk> chunks;
  uint64_t chunkTableOffset = 0;
};

// Reads the header, the LASzip VLR and the chunk table of a LAZ file, checking every offset, size and
// count against the file and each other. Throws InputError naming the file with one sentence, also for
// encodings pointrast does not decode (waveform packets, LASzip 1.x items).
LazFile openLaz(const detail::InputFile& file);

// Parses the payload of a LASzip VLR for a file of `pointFormat` records of `recordLength` bytes.
Layout parseLaszipVlr(const std::filesystem::path& path, const uint8_t* data, size_t size, int pointFormat,
                      uint16_t recordLength);

// The chunk table's bytes for `chunks` (version 0, count, then the arithmetic-coded sizes and, with
// variable chunks, counts), as LASzip writes it.
std::vector<uint8_t> encodeChunkTable(const std::vector<Chunk>& chunks, bool variableChunks);

// Decodes chunk table bytes (what follows the table's offset) into byte sizes and counts; counts stay
// 0 unless variableChunks. Throws InputError via path on damaged bytes. maxChunks bounds the claimed count.
std::vector<Chunk> decodeChunkTable(const std::filesystem::path& path, const uint8_t* data, size_t size,
                                    bool variableChunks, uint64_t maxChunks);

} // namespace pointrast::io::laz
