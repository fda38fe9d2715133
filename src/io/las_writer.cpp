// LAS writer: 1.2 point formats 2 and 3, 1.4 point format 7 (ASPRS LAS 1.4 R15). No VLRs, so the
// points follow the header directly. Records are built in chunks and written through PartialFile.
#include <ctime>

#include "io/las_format.h"
#include "io/writer.h"

namespace pointrast::io {

using namespace detail;

namespace {

constexpr uint64_t kChunkPoints = uint64_t(1) << 16;

struct FlavorInfo {
  uint8_t minor;
  int pointFormat;
  uint64_t headerSize;
};

FlavorInfo flavorInfo(LasFlavor flavor) {
  switch (flavor) {
  case LasFlavor::Las12Pf2:
    return {2, 2, las::kHeaderSize12};
  case LasFlavor::Las12Pf3:
    return {2, 3, las::kHeaderSize12};
  case LasFlavor::Las14Pf7:
    return {4, 7, las::kHeaderSize14};
  }
  return {2, 3, las::kHeaderSize12};
}

void copyString(uint8_t* dst, size_t n, const char* s) {
  std::memset(dst, 0, n);
  std::memcpy(dst, s, std::min(n, std::strlen(s)));
}

} // namespace

void writeLas(const std::filesystem::path& path, const PointCloud& cloud, LasFlavor flavor) {
  const FlavorInfo f = flavorInfo(flavor);
  const uint64_t n = cloud.size();
  const uint16_t recordLength = las::kRecordSize[static_cast<size_t>(f.pointFormat)];
  if (f.minor < 4 && n > UINT32_MAX)
    fail(path, strFormat("%llu points do not fit in LAS 1.2 (at most 4294967295); write LAS 1.4",
                         static_cast<unsigned long long>(n)));
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(cloud.scale[a]) || cloud.scale[a] == 0.0 || !std::isfinite(cloud.offset[a]))
      fail(path, "the cloud's scale/offset cannot be written as LAS");
  // Attributes are used only when they match the point count (an empty array means "none").
  const bool color = cloud.colors.size() == n && n > 0;
  const bool intensity = cloud.intensity.size() == n && n > 0;
  const bool classification = cloud.classification.size() == n && n > 0;
  const bool returns = cloud.returnNumber.size() == n && n > 0;
  const bool sourceIds = cloud.pointSourceId.size() == n && n > 0;
  const bool extended = las::isExtended(f.pointFormat);
  const int rgbOffset = las::kRgbOffset[static_cast<size_t>(f.pointFormat)];

  // Bounds from the stored integers: exactly what a reader computes, even if cloud.bounds is stale.
  int32_t qmin[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, qmax[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  std::array<uint64_t, 15> byReturn{};
  for (uint64_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      qmin[a] = std::min(qmin[a], cloud.positions[3 * i + a]);
      qmax[a] = std::max(qmax[a], cloud.positions[3 * i + a]);
    }
    int r = returns ? cloud.returnNumber[i] : 1;
    if (r >= 1 && r <= (extended ? 15 : 5)) ++byReturn[static_cast<size_t>(r - 1)];
  }
  Bounds bounds;
  if (n > 0)
    bounds = boundsFromQuantized(qmin, qmax, cloud.scale, cloud.offset);
  else
    bounds.min = bounds.max = glm::dvec3(0);

  // Public header block, R15 Table 3 (offsets in las_format.h).
  uint8_t h[las::kHeaderSize14] = {};
  std::memcpy(h, "LASF", 4);
  // Global encoding bit 4: CRS (if any) is WKT, required for point formats 6-10 (R15 2.4).
  storeLE<uint16_t>(h + las::kGlobalEncoding, extended ? 0x10 : 0);
  h[las::kVersionMajor] = 1;
  h[las::kVersionMinor] = f.minor;
  copyString(h + las::kSystemId, 32, "pointrast");
  copyString(h + las::kSoftware, 32, "pointrast");
  std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  storeLE<uint16_t>(h + las::kCreationDay, static_cast<uint16_t>(utc.tm_yday + 1));
  storeLE<uint16_t>(h + las::kCreationYear, static_cast<uint16_t>(utc.tm_year + 1900));
  storeLE<uint16_t>(h + las::kHeaderSizeField, static_cast<uint16_t>(f.headerSize));
  storeLE<uint32_t>(h + las::kPointOffset, static_cast<uint32_t>(f.headerSize));
  storeLE<uint32_t>(h + las::kVlrCount, 0);
  h[las::kPointFormat] = static_cast<uint8_t>(f.pointFormat);
  storeLE<uint16_t>(h + las::kRecordLength, recordLength);
  // The legacy count fields stay 0 for formats 6-10 (R15 2.4).
  if (!extended) {
    storeLE<uint32_t>(h + las::kLegacyCount, static_cast<uint32_t>(n));
    for (int i = 0; i < 5; ++i)
      storeLE<uint32_t>(h + las::kLegacyByReturn + 4 * i, static_cast<uint32_t>(byReturn[i]));
  }
  for (int a = 0; a < 3; ++a) {
    storeLE<double>(h + las::kScale + 8 * a, cloud.scale[a]);
    storeLE<double>(h + las::kOffset + 8 * a, cloud.offset[a]);
    storeLE<double>(h + las::kMaxX + 16 * a, bounds.max[a]);
    storeLE<double>(h + las::kMaxX + 16 * a + 8, bounds.min[a]);
  }
  if (f.minor >= 4) {
    storeLE<uint64_t>(h + las::kCount64, n);
    for (int i = 0; i < 15; ++i)
      storeLE<uint64_t>(h + las::kByReturn64 + 8 * i, byReturn[i]);
  }

  PartialFile out(path);
  out.write(h, f.headerSize);
  std::vector<uint8_t> buffer(static_cast<size_t>(std::min(n, kChunkPoints) * recordLength));
  for (uint64_t first = 0; first < n; first += kChunkPoints) {
    uint64_t count = std::min(kChunkPoints, n - first);
    std::fill(buffer.begin(), buffer.end(), 0);
    for (uint64_t k = 0; k < count; ++k) {
      uint64_t i = first + k;
      uint8_t* r = buffer.data() + k * recordLength;
      for (int a = 0; a < 3; ++a)
        storeLE<int32_t>(r + 4 * a, cloud.positions[3 * i + a]);
      storeLE<uint16_t>(r + 12, intensity ? cloud.intensity[i] : 0);
      // Number of returns is not kept by PointCloud; writing it equal to the return number keeps the
      // record valid (return number <= number of returns).
      uint8_t rn = returns ? cloud.returnNumber[i] : 1;
      uint8_t cls = classification ? cloud.classification[i] : 0;
      if (extended) {
        rn &= 0x0F;
        r[14] = static_cast<uint8_t>(rn | (rn << 4)); // return number bits 0-3, number of returns 4-7
        r[16] = cls;
        storeLE<uint16_t>(r + 20, sourceIds ? cloud.pointSourceId[i] : 0);
      } else {
        rn &= 0x07;
        r[14] = static_cast<uint8_t>(rn | (rn << 3)); // return number bits 0-2, number of returns 3-5
        r[15] = cls & 0x1F;                           // classes above 31 do not fit formats 0-5
        storeLE<uint16_t>(r + 18, sourceIds ? cloud.pointSourceId[i] : 0);
      }
      if (color) {
        // 16-bit channels: v * 257 (= v << 8 | v) maps 0..255 onto the full 0..65535 range.
        uint32_t c = cloud.colors[i];
        for (int ch = 0; ch < 3; ++ch)
          storeLE<uint16_t>(r + rgbOffset + 2 * ch, static_cast<uint16_t>(((c >> (8 * ch)) & 0xFF) * 257));
      }
    }
    out.write(buffer.data(), static_cast<size_t>(count * recordLength));
  }
  out.commit();
}

} // namespace pointrast::io
