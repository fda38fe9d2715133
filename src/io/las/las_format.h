// The LAS public header and point record layouts, after ASPRS "LAS Specification 1.4 - R15" (2019).
// Shared by the LAS reader, the LAS writer and format detection.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "io/io_util.h"

namespace pointrast::io::detail {

// Public header block offsets (R15 section 2.4, Table 3). 1.0-1.2 headers end at 227, 1.3 adds the
// waveform start (235), 1.4 the EVLR fields and 64-bit counts (375).
namespace las {
inline constexpr uint64_t kHeaderSize12 = 227;
inline constexpr uint64_t kHeaderSize13 = 235;
inline constexpr uint64_t kHeaderSize14 = 375;
inline constexpr uint64_t kVlrHeaderSize = 54; // R15 section 2.5, Table 4

// A fixed-size character field: `s` cut to `n` bytes, the rest zero (LAS strings need no terminator).
inline void copyString(uint8_t* dst, size_t n, const char* s) {
  std::memset(dst, 0, n);
  std::memcpy(dst, s, std::min(n, std::strlen(s)));
}

// A variable length record: its 54-byte header (R15 Table 4) followed by `payload`.
inline std::vector<uint8_t> vlrBytes(const char* userId, uint16_t recordId, const char* description,
                                     const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> v(kVlrHeaderSize + payload.size(), 0);
  copyString(v.data() + 2, 16, userId);
  storeLE<uint16_t>(v.data() + 18, recordId);
  storeLE<uint16_t>(v.data() + 20, static_cast<uint16_t>(payload.size()));
  copyString(v.data() + 22, 32, description);
  std::memcpy(v.data() + kVlrHeaderSize, payload.data(), payload.size());
  return v;
}

inline constexpr int kFileSourceId = 4;
inline constexpr int kGlobalEncoding = 6;
inline constexpr int kVersionMajor = 24;
inline constexpr int kVersionMinor = 25;
inline constexpr int kSystemId = 26; // char[32]
inline constexpr int kSoftware = 58; // char[32]
inline constexpr int kCreationDay = 90;
inline constexpr int kCreationYear = 92;
inline constexpr int kHeaderSizeField = 94;
inline constexpr int kPointOffset = 96;
inline constexpr int kVlrCount = 100;
inline constexpr int kPointFormat = 104;
inline constexpr int kRecordLength = 105;
inline constexpr int kLegacyCount = 107;
inline constexpr int kLegacyByReturn = 111; // uint32[5]
inline constexpr int kScale = 131;          // double[3]
inline constexpr int kOffset = 155;         // double[3]
inline constexpr int kMaxX = 179;           // then min x, max y, min y, max z, min z
inline constexpr int kWaveformStart = 227;  // 1.3+
inline constexpr int kEvlrStart = 235;      // 1.4
inline constexpr int kEvlrCount = 243;
inline constexpr int kCount64 = 247;
inline constexpr int kByReturn64 = 255; // uint64[15]

// Point data record formats 0-10 (R15 section 2.6). Formats 6-10 ("extended") have 4-bit return
// numbers, the classification in its own byte at 16 and a 16-bit scan angle.
inline constexpr int kMaxPointFormat = 10;
inline constexpr std::array<uint16_t, 11> kRecordSize = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
// Byte offset of the red/green/blue uint16 triple, or -1 when the format has no color.
inline constexpr std::array<int, 11> kRgbOffset = {-1, -1, 20, 28, -1, 28, -1, 30, 30, -1, 30};
inline bool isExtended(int pointFormat) {
  return pointFormat >= 6;
}
// Waveform formats and the format of their records without the 29-byte wave packet: the packet starts
// where the base format's record ends.
inline int withoutWaveform(int pointFormat) {
  switch (pointFormat) {
  case 4:
    return 1;
  case 5:
    return 3;
  case 9:
    return 6;
  case 10:
    return 8;
  default:
    return pointFormat;
  }
}

// Bits 7 and 6 of the point format byte are set by LASzip in compressed files (the format is the low 6).
inline constexpr uint8_t kCompressionBits = 0xC0;
} // namespace las

struct LasVlr {
  std::string userId;
  uint16_t recordId = 0;
  uint16_t length = 0;
  std::string description;
  uint64_t dataOffset = 0; // file offset of the record's payload (length bytes)
};

struct LasHeader {
  uint8_t versionMajor = 0, versionMinor = 0;
  uint16_t fileSourceId = 0, globalEncoding = 0;
  std::string systemId, software;
  uint16_t creationDay = 0, creationYear = 0;
  uint16_t headerSize = 0;
  uint32_t pointOffset = 0;
  uint32_t vlrCount = 0;
  uint8_t pointFormatByte = 0;
  int pointFormat = 0; // pointFormatByte without the compression bits
  uint16_t recordLength = 0;
  uint32_t legacyCount = 0;
  uint64_t pointCount = 0; // the 64-bit count for 1.4, the legacy count before
  std::array<uint64_t, 15> pointsByReturn{};
  glm::dvec3 scale{0}, offset{0};
  Bounds bounds; // as stated by the header (may be all zero in valid files)
  uint64_t waveformStart = 0, evlrStart = 0;
  uint32_t evlrCount = 0;
  std::vector<LasVlr> vlrs;
  bool vlrsTruncated = false; // the VLR chain runs past the point data; listed as far as it is sound
  bool compressed = false;    // LAZ: compression bits or a LASzip / COPC VLR

  int rgbOffset() const { return las::kRgbOffset[static_cast<size_t>(pointFormat)]; }
  bool hasColor() const { return rgbOffset() >= 0; }
};

// Whether the bytes look like LAZ/COPC: the "LASF" magic with a compression bit, or a LASzip or COPC
// VLR. Tolerant (used by detectFormat): a damaged header just reads as "not compressed".
bool lasLooksCompressed(const InputFile& file);

// Reads and validates the header and VLR list: every size, offset and count is checked against the file
// size, so a header that passes can be used to read point data without further bounds checks. Throws
// InputError with one sentence; for compressed files failCompressed()'s sentence unless allowCompressed,
// in which case the point count is left for the LAZ reader to check against its chunk table.
LasHeader readLasHeader(const InputFile& file, bool allowCompressed = false);

// Bytes of point records the LAS reader reads and parses at a time (default 32 MiB). Tests lower it to
// cross chunk boundaries with small files; 0 restores the default.
void setLasChunkBytes(uint64_t bytes);
uint64_t lasChunkBytes();

// The sentence the plain LAS reader gives for LAZ/COPC files (readCloud sends those to the LAZ reader).
[[noreturn]] void failCompressed(const std::filesystem::path& path);

} // namespace pointrast::io::detail
