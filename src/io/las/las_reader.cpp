// LAS 1.0-1.4 reader, point formats 0-10 (ASPRS LAS 1.4 R15). Point records are read in chunks of
// ~32 MiB with positional reads (the next chunk is read while the current one is parsed), and each
// chunk is parsed in parallel blocks straight into the PointCloud arrays, which are sized once from the
// validated header count: memory is the cloud itself plus two chunk buffers.
#include <atomic>
#include <climits>
#include <optional>

#include "base/parallel.h"
#include "base/progress.h"
#include "io/formats.h"
#include "io/las/las_format.h"
#include "io/las/las_range.h"
#include "io/las/las_records.h"

namespace pointrast::io {

using namespace detail;

namespace {

constexpr uint64_t kDefaultChunkBytes = uint64_t(32) << 20;
std::atomic<uint64_t> gChunkBytes{kDefaultChunkBytes};
constexpr uint64_t kBlockPoints = uint64_t(1) << 16; // parallel work unit within a chunk

// Calls fn(records, firstIndex, count) for consecutive chunks of point records (see forEachRecordChunk).
template <class Fn> void forEachChunk(const InputFile& file, const LasHeader& hd, Fn&& fn) {
  forEachRecordChunk(file, hd.pointOffset, hd.pointCount, hd.recordLength, lasChunkBytes(), fn);
}
// The same for records [first, first + count) (inside the header's count); firstIndex counts from first.
template <class Fn>
void forEachChunk(const InputFile& file, const LasHeader& hd, uint64_t first, uint64_t count, Fn&& fn) {
  forEachRecordChunk(file, hd.pointOffset + first * hd.recordLength, count, hd.recordLength, lasChunkBytes(),
                     fn);
}

// 8-bit value from a 16-bit LAS color channel: shift is 8 for files with 16-bit colors, else 0.
inline uint32_t packLasColor(const uint8_t* rgb, int shift) {
  uint32_t r = (loadLE<uint16_t>(rgb) >> shift) & 0xFF;
  uint32_t g = (loadLE<uint16_t>(rgb + 2) >> shift) & 0xFF;
  uint32_t b = (loadLE<uint16_t>(rgb + 4) >> shift) & 0xFF;
  return packRgba(r, g, b);
}

// R15 2.4 stores the creation date as year + day of year (1 = January 1st); shown as an ISO date.
std::string creationDate(const LasHeader& hd) {
  const unsigned year = hd.creationYear, day = hd.creationDay;
  if (year == 0 && day == 0) return "not set";
  const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
  const unsigned monthDays[12] = {31, leap ? 29u : 28u, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  unsigned left = day;
  for (unsigned m = 0; m < 12 && left >= 1; ++m) {
    if (left <= monthDays[m]) return strFormat("%04u-%02u-%02u (day %u)", year, m + 1, left, day);
    left -= monthDays[m];
  }
  return strFormat("year %u, day %u (not a valid date)", year, day);
}

// R15 2.4, Table 3 note: global encoding bits.
std::string describeGlobalEncoding(uint16_t bits) {
  static const char* const kNames[] = {"GPS standard time", "waveform data internal",
                                       "waveform data external", "synthetic return numbers", "WKT CRS"};
  std::string s = std::to_string(bits);
  std::string names;
  for (int i = 0; i < 5; ++i)
    if (bits & (1u << i)) names += strFormat(names.empty() ? "%s" : ", %s", kNames[i]);
  return names.empty() ? s : s + " (" + names + ")";
}

} // namespace

PointCloud readLas(const std::filesystem::path& path, const ReadOptions& options) {
  return readLasRecords(path, options, 0, UINT64_MAX, nullptr);
}

PointCloud readLasRecords(const std::filesystem::path& path, const ReadOptions& options, uint64_t firstRecord,
                          uint64_t recordCount, uint16_t* colorMax) {
  InputFile file(path);
  const LasHeader hd = readLasHeader(file);
  firstRecord = std::min(firstRecord, hd.pointCount);
  const uint64_t n = std::min(recordCount, hd.pointCount - firstRecord);
  const bool extended = las::isExtended(hd.pointFormat);
  const int rgbOffset = hd.rgbOffset();

  PointCloud cloud;
  cloud.source = path.filename().string();
  cloud.scale = hd.scale;
  cloud.offset = hd.offset;
  // n was checked against the bytes present (n * recordLength <= file size), so these allocations are
  // bounded by the file: at most 20 B per 20 B record.
  cloud.positions.resize(3 * n);
  if (hd.hasColor()) cloud.colors.resize(n);
  if (options.keepAttributes) {
    cloud.intensity.resize(n);
    cloud.classification.resize(n);
    cloud.returnNumber.resize(n);
    cloud.pointSourceId.resize(n);
  }
  RecordDestination all;
  all.positions = cloud.positions.data();
  all.colors = hd.hasColor() ? cloud.colors.data() : nullptr;
  if (options.keepAttributes) {
    all.intensity = cloud.intensity.data();
    all.classification = cloud.classification.data();
    all.returnNumber = cloud.returnNumber.data();
    all.pointSourceId = cloud.pointSourceId.data();
  }

  std::optional<Progress> progress;
  if (options.progress) progress.emplace("reading " + path.filename().string(), n);

  RecordStats total;
  bool colors16 = false; // decided per file: any channel above 255 means 16-bit colors
  std::vector<RecordStats> stats;
  uint16_t fileColorMax = 0;
  forEachChunk(file, hd, firstRecord, n, [&](const uint8_t* records, uint64_t first, uint64_t count) {
    stats.assign((count + kBlockPoints - 1) / kBlockPoints, RecordStats{});
    int shift = colors16 ? 8 : 0;
    parallelBlocks(count, kBlockPoints, [&](uint64_t block, uint64_t begin, uint64_t end) {
      const uint8_t* src = records + begin * hd.recordLength;
      RecordDestination d = offsetBy(all, first + begin);
      if (extended)
        parseRecords<true>(src, hd.recordLength, end - begin, rgbOffset, shift, d, stats[block]);
      else
        parseRecords<false>(src, hd.recordLength, end - begin, rgbOffset, shift, d, stats[block]);
      if (progress) progress->advance(end - begin);
    });
    uint16_t chunkColorMax = 0;
    for (const RecordStats& s : stats) {
      for (int a = 0; a < 3; ++a) {
        total.qmin[a] = std::min(total.qmin[a], s.qmin[a]);
        total.qmax[a] = std::max(total.qmax[a], s.qmax[a]);
      }
      chunkColorMax = std::max(chunkColorMax, s.colorMax);
    }
    fileColorMax = std::max(fileColorMax, chunkColorMax);
    if (all.colors && !colors16 && chunkColorMax > 255) {
      // The first value above 255: the file is 16-bit. Earlier chunks held only values <= 255, which
      // are 0 in 8-bit terms; this chunk is converted again with the 16-bit shift.
      colors16 = true;
      std::fill(cloud.colors.begin(), cloud.colors.begin() + static_cast<ptrdiff_t>(first),
                packRgba(0, 0, 0));
      parallelBlocks(count, kBlockPoints, [&](uint64_t, uint64_t begin, uint64_t end) {
        for (uint64_t i = begin; i < end; ++i)
          all.colors[first + i] = packLasColor(records + i * hd.recordLength + rgbOffset, 8);
      });
    }
  });
  if (progress) progress->finish();
  if (colorMax) *colorMax = fileColorMax;

  if (n > 0) {
    cloud.bounds = boundsFromQuantized(total.qmin, total.qmax, cloud.scale, cloud.offset);
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(cloud.bounds.min[a]) || !std::isfinite(cloud.bounds.max[a]))
        fail(path, "coordinates overflow after applying the header's scale and offset");
  }
  return cloud;
}

namespace detail {

void setLasChunkBytes(uint64_t bytes) {
  gChunkBytes = bytes ? bytes : kDefaultChunkBytes;
}
uint64_t lasChunkBytes() {
  return gChunkBytes;
}

FileInfo describeLasHeader(const LasHeader& hd, const char* name, uint16_t colorLo, uint16_t colorHi) {
  FileInfo info;
  uint16_t formatSize = las::kRecordSize[static_cast<size_t>(hd.pointFormat)];
  info.formatDetail = strFormat("%s %d.%d, point format %d (%u B records", name, hd.versionMajor,
                                hd.versionMinor, hd.pointFormat, hd.recordLength);
  if (hd.recordLength > formatSize)
    info.formatDetail += strFormat(": %u + %u extra bytes", formatSize, hd.recordLength - formatSize);
  info.formatDetail += ")";
  info.pointCount = hd.pointCount;
  info.bounds = hd.bounds;
  info.boundsFromHeader = true;
  info.scale = hd.scale;
  info.offset = hd.offset;
  info.hasColor = hd.hasColor();

  auto& extra = info.extra;
  if (info.hasColor) {
    // The bit depth is a property of the values, not the header.
    info.colorBits = colorHi > 255 ? 16 : 8;
    if (hd.pointCount > 0) extra.emplace_back("color values", strFormat("%u .. %u", colorLo, colorHi));
  }
  extra.emplace_back("system identifier", hd.systemId.empty() ? "(empty)" : hd.systemId);
  extra.emplace_back("generating software", hd.software.empty() ? "(empty)" : hd.software);
  extra.emplace_back("creation date", creationDate(hd));
  extra.emplace_back("file source id", std::to_string(hd.fileSourceId));
  extra.emplace_back("global encoding", describeGlobalEncoding(hd.globalEncoding));
  extra.emplace_back("header size", strFormat("%u B", hd.headerSize));
  extra.emplace_back("offset to point data", strFormat("%u", hd.pointOffset));
  std::string byReturn;
  int returns = las::isExtended(hd.pointFormat) || hd.versionMinor >= 4 ? 15 : 5;
  int last = 0;
  for (int i = 0; i < returns; ++i)
    if (hd.pointsByReturn[i]) last = i + 1;
  for (int i = 0; i < std::max(last, 5); ++i)
    byReturn += strFormat(i ? " %llu" : "%llu", static_cast<unsigned long long>(hd.pointsByReturn[i]));
  extra.emplace_back("points by return (header)", byReturn);
  std::string vlrs = std::to_string(hd.vlrCount);
  for (size_t i = 0; i < hd.vlrs.size(); ++i)
    vlrs += strFormat("%s%s %u (%u B)", i ? ", " : ": ", hd.vlrs[i].userId.c_str(), hd.vlrs[i].recordId,
                      hd.vlrs[i].length);
  if (hd.vlrsTruncated) vlrs += strFormat("; the list runs past the point data, %zu listed", hd.vlrs.size());
  extra.emplace_back("VLRs", vlrs);
  if (hd.versionMinor >= 4)
    extra.emplace_back(
        "EVLRs", strFormat("%u at offset %llu", hd.evlrCount, static_cast<unsigned long long>(hd.evlrStart)));
  return info;
}

FileInfo probeLas(const std::filesystem::path& path) {
  InputFile file(path);
  const LasHeader hd = readLasHeader(file);
  uint16_t lo = UINT16_MAX, hi = 0;
  if (hd.hasColor()) {
    const int rgbOffset = hd.rgbOffset();
    forEachChunk(file, hd, [&](const uint8_t* records, uint64_t, uint64_t count) {
      for (uint64_t i = 0; i < count; ++i) {
        const uint8_t* rgb = records + i * hd.recordLength + rgbOffset;
        for (int c = 0; c < 3; ++c) {
          uint16_t v = loadLE<uint16_t>(rgb + 2 * c);
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
      }
    });
  }
  return describeLasHeader(hd, "LAS", lo, hi);
}

} // namespace detail

} // namespace pointrast::io
