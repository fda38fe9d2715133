#include "io/las/las_format.h"

#include <cmath>

namespace pointrast::io::detail {

namespace {

std::string fixedString(const uint8_t* p, size_t n) {
  size_t len = 0;
  while (len < n && p[len] != 0)
    ++len;
  std::string s(reinterpret_cast<const char*>(p), len);
  // Display only: keep printable ASCII, so a hostile header cannot put control sequences on a terminal.
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  while (!s.empty() && s.back() == ' ')
    s.pop_back();
  return s;
}

bool isCompressionVlr(const LasVlr& vlr) {
  // LASzip: user id "laszip encoded", record 22204; COPC: user id "copc" (COPC 1.0 spec, info VLR 1).
  return vlr.userId == "laszip encoded" || vlr.userId == "copc";
}

// Walks the VLR chain from start, at most count records, never past limit. Sets truncated when the
// chain claims more than fits.
std::vector<LasVlr> walkVlrs(const InputFile& file, uint64_t start, uint32_t count, uint64_t limit,
                             bool& truncated) {
  std::vector<LasVlr> vlrs;
  truncated = false;
  uint64_t pos = start;
  for (uint32_t i = 0; i < count; ++i) {
    if (limit < las::kVlrHeaderSize || pos > limit - las::kVlrHeaderSize) {
      truncated = true;
      break;
    }
    uint8_t h[las::kVlrHeaderSize];
    file.readAt(pos, h, sizeof h);
    LasVlr vlr;
    // R15 Table 4: reserved u16, user id char[16], record id u16, length after header u16,
    // description char[32].
    vlr.userId = fixedString(h + 2, 16);
    vlr.recordId = loadLE<uint16_t>(h + 18);
    vlr.length = loadLE<uint16_t>(h + 20);
    vlr.description = fixedString(h + 22, 32);
    pos += las::kVlrHeaderSize;
    vlr.dataOffset = pos;
    if (vlr.length > limit - pos) {
      truncated = true;
      vlrs.push_back(std::move(vlr));
      break;
    }
    pos += vlr.length;
    vlrs.push_back(std::move(vlr));
  }
  return vlrs;
}

} // namespace

void failCompressed(const std::filesystem::path& path) {
  fail(path, "the points are LAZ-compressed; the plain LAS reader reads uncompressed files only");
}

bool lasLooksCompressed(const InputFile& file) {
  uint8_t h[las::kHeaderSize12];
  if (file.size() < sizeof h) return false;
  file.readAt(0, h, sizeof h);
  if (std::memcmp(h, "LASF", 4) != 0) return false;
  if (h[las::kPointFormat] & las::kCompressionBits) return true;
  uint16_t headerSize = loadLE<uint16_t>(h + las::kHeaderSizeField);
  if (headerSize < las::kHeaderSize12 || headerSize > file.size()) return false;
  bool truncated = false;
  for (const LasVlr& vlr :
       walkVlrs(file, headerSize, loadLE<uint32_t>(h + las::kVlrCount), file.size(), truncated))
    if (isCompressionVlr(vlr)) return true;
  return false;
}

LasHeader readLasHeader(const InputFile& file, bool allowCompressed) {
  const std::filesystem::path& path = file.path();
  const uint64_t fileSize = file.size();
  if (fileSize < las::kHeaderSize12)
    fail(path, strFormat("file is %llu bytes, too short for a LAS header (227 bytes)",
                         static_cast<unsigned long long>(fileSize)));
  uint8_t h[las::kHeaderSize14] = {};
  file.readAt(0, h, static_cast<size_t>(std::min<uint64_t>(fileSize, sizeof h)));
  if (std::memcmp(h, "LASF", 4) != 0) fail(path, "not a LAS file (no LASF signature)");

  LasHeader hd;
  hd.fileSourceId = loadLE<uint16_t>(h + las::kFileSourceId);
  hd.globalEncoding = loadLE<uint16_t>(h + las::kGlobalEncoding);
  hd.versionMajor = h[las::kVersionMajor];
  hd.versionMinor = h[las::kVersionMinor];
  hd.systemId = fixedString(h + las::kSystemId, 32);
  hd.software = fixedString(h + las::kSoftware, 32);
  hd.creationDay = loadLE<uint16_t>(h + las::kCreationDay);
  hd.creationYear = loadLE<uint16_t>(h + las::kCreationYear);
  hd.headerSize = loadLE<uint16_t>(h + las::kHeaderSizeField);
  hd.pointOffset = loadLE<uint32_t>(h + las::kPointOffset);
  hd.vlrCount = loadLE<uint32_t>(h + las::kVlrCount);
  hd.pointFormatByte = h[las::kPointFormat];
  hd.pointFormat = hd.pointFormatByte & ~las::kCompressionBits;
  hd.recordLength = loadLE<uint16_t>(h + las::kRecordLength);
  hd.legacyCount = loadLE<uint32_t>(h + las::kLegacyCount);
  for (int i = 0; i < 5; ++i)
    hd.pointsByReturn[i] = loadLE<uint32_t>(h + las::kLegacyByReturn + 4 * i);
  for (int a = 0; a < 3; ++a) {
    hd.scale[a] = loadLE<double>(h + las::kScale + 8 * a);
    hd.offset[a] = loadLE<double>(h + las::kOffset + 8 * a);
    hd.bounds.max[a] = loadLE<double>(h + las::kMaxX + 16 * a);
    hd.bounds.min[a] = loadLE<double>(h + las::kMaxX + 16 * a + 8);
  }

  if (hd.versionMajor != 1 || hd.versionMinor > 4)
    fail(path,
         strFormat("LAS version %d.%d is not supported (1.0 to 1.4 are)", hd.versionMajor, hd.versionMinor));
  if (hd.headerSize < las::kHeaderSize12)
    fail(path, strFormat("header size %u is smaller than the 227 bytes of a LAS header", hd.headerSize));
  if (hd.headerSize > fileSize)
    fail(path, strFormat("header size %u is larger than the file (%llu bytes)", hd.headerSize,
                         static_cast<unsigned long long>(fileSize)));
  if (hd.versionMinor >= 4 && hd.headerSize < las::kHeaderSize14)
    fail(path, strFormat("LAS 1.4 header size %u is smaller than the 375 bytes it needs", hd.headerSize));
  if (hd.versionMinor >= 3) hd.waveformStart = loadLE<uint64_t>(h + las::kWaveformStart);
  hd.pointCount = hd.legacyCount;
  if (hd.versionMinor >= 4) {
    hd.evlrStart = loadLE<uint64_t>(h + las::kEvlrStart);
    hd.evlrCount = loadLE<uint32_t>(h + las::kEvlrCount);
    // R15 2.4: the legacy count must be 0 for formats 6-10 and may be 0 when the count exceeds 2^32-1;
    // the 64-bit field is authoritative. Some 1.4 writers leave it 0 with a legacy count: use that.
    uint64_t count64 = loadLE<uint64_t>(h + las::kCount64);
    if (count64 != 0) hd.pointCount = count64;
    for (int i = 0; i < 15; ++i)
      hd.pointsByReturn[i] = loadLE<uint64_t>(h + las::kByReturn64 + 8 * i);
  }

  if (hd.pointOffset < hd.headerSize || hd.pointOffset > fileSize)
    fail(path, strFormat("point data offset %u is outside the file (header %u bytes, file %llu bytes)",
                         hd.pointOffset, hd.headerSize, static_cast<unsigned long long>(fileSize)));
  hd.vlrs = walkVlrs(file, hd.headerSize, hd.vlrCount, hd.pointOffset, hd.vlrsTruncated);
  hd.compressed = (hd.pointFormatByte & las::kCompressionBits) != 0;
  for (const LasVlr& vlr : hd.vlrs)
    hd.compressed = hd.compressed || isCompressionVlr(vlr);
  if (hd.compressed && !allowCompressed) failCompressed(path);

  if (hd.pointFormat > las::kMaxPointFormat)
    fail(path, strFormat("point format %d is not a LAS point format (0 to 10)", hd.pointFormat));
  uint16_t formatSize = las::kRecordSize[static_cast<size_t>(hd.pointFormat)];
  if (hd.recordLength < formatSize)
    fail(path, strFormat("point record length %u is shorter than the %u bytes of point format %d",
                         hd.recordLength, formatSize, hd.pointFormat));
  static const char kAxis[] = "xyz";
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(hd.scale[a]) || hd.scale[a] == 0.0)
      fail(path, strFormat("%c scale factor %g is not usable", kAxis[a], hd.scale[a]));
    if (!std::isfinite(hd.offset[a]))
      fail(path, strFormat("%c offset %g is not a finite number", kAxis[a], hd.offset[a]));
  }
  uint64_t available = fileSize - hd.pointOffset;
  if (!hd.compressed && hd.pointCount > available / hd.recordLength)
    fail(path, strFormat("header claims %llu points of %u bytes but the file holds %llu bytes of point data",
                         static_cast<unsigned long long>(hd.pointCount), hd.recordLength,
                         static_cast<unsigned long long>(available)));
  return hd;
}

} // namespace pointrast::io::detail
