// LAS writer: 1.2 point formats 2 and 3, 1.4 point format 7 (ASPRS LAS 1.4 R15). No VLRs, so the
// points follow the header directly. Records are built in chunks and written through PartialFile; the
// header, whose counts and bounds depend on every point, is written last over a placeholder.
#include <ctime>
#include <optional>

#include "io/las/las_format.h"
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

struct LasRecordWriter::State {
  State(const std::filesystem::path& p, LasFlavor flavor) : f(flavorInfo(flavor)), path(p) {}

  FlavorInfo f;
  std::filesystem::path path;
  std::optional<PartialFile> out;
  uint16_t recordLength = 0;
  glm::dvec3 scale{1.0}, offset{0.0};
  RecordFields fields;
  uint64_t count = 0;
  int32_t qmin[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, qmax[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  std::array<uint64_t, 15> byReturn{};
  std::vector<uint8_t> buffer;

  void encode(const PointRecord* records, size_t n);
  void header(uint8_t* h) const;
};

void LasRecordWriter::State::encode(const PointRecord* records, size_t n) {
  const bool extended = las::isExtended(f.pointFormat);
  const int rgbOffset = las::kRgbOffset[static_cast<size_t>(f.pointFormat)];
  buffer.assign(n * recordLength, 0);
  for (size_t k = 0; k < n; ++k) {
    const PointRecord& p = records[k];
    uint8_t* r = buffer.data() + k * recordLength;
    const int32_t q[3] = {p.x, p.y, p.z};
    for (int a = 0; a < 3; ++a) {
      storeLE<int32_t>(r + 4 * a, q[a]);
      qmin[a] = std::min(qmin[a], q[a]);
      qmax[a] = std::max(qmax[a], q[a]);
    }
    storeLE<uint16_t>(r + 12, fields.intensity ? p.intensity : 0);
    // Number of returns is not kept by records; writing it equal to the return number keeps the record
    // valid (return number <= number of returns).
    uint8_t rn = fields.returnNumber ? p.returnNumber : 1;
    const uint8_t cls = fields.classification ? p.classification : 0;
    if (extended) {
      rn &= 0x0F;
      r[14] = static_cast<uint8_t>(rn | (rn << 4)); // return number bits 0-3, number of returns 4-7
      r[16] = cls;
      storeLE<uint16_t>(r + 20, fields.pointSourceId ? p.pointSourceId : 0);
    } else {
      rn &= 0x07;
      r[14] = static_cast<uint8_t>(rn | (rn << 3)); // return number bits 0-2, number of returns 3-5
      r[15] = cls & 0x1F;                           // classes above 31 do not fit formats 0-5
      storeLE<uint16_t>(r + 18, fields.pointSourceId ? p.pointSourceId : 0);
    }
    if (rn >= 1 && rn <= (extended ? 15 : 5)) ++byReturn[static_cast<size_t>(rn - 1)];
    if (fields.color && rgbOffset >= 0)
      for (int ch = 0; ch < 3; ++ch)
        storeLE<uint16_t>(r + rgbOffset + 2 * ch, p.rgb[ch]);
  }
}

// Public header block, R15 Table 3 (offsets in las_format.h), for the points written so far.
void LasRecordWriter::State::header(uint8_t* h) const {
  const bool extended = las::isExtended(f.pointFormat);
  Bounds bounds;
  if (count > 0)
    bounds = boundsFromQuantized(qmin, qmax, scale, offset); // exactly what a reader computes
  else
    bounds.min = bounds.max = glm::dvec3(0);
  std::memset(h, 0, las::kHeaderSize14);
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
    storeLE<uint32_t>(h + las::kLegacyCount, static_cast<uint32_t>(count));
    for (int i = 0; i < 5; ++i)
      storeLE<uint32_t>(h + las::kLegacyByReturn + 4 * i, static_cast<uint32_t>(byReturn[i]));
  }
  for (int a = 0; a < 3; ++a) {
    storeLE<double>(h + las::kScale + 8 * a, scale[a]);
    storeLE<double>(h + las::kOffset + 8 * a, offset[a]);
    storeLE<double>(h + las::kMaxX + 16 * a, bounds.max[a]);
    storeLE<double>(h + las::kMaxX + 16 * a + 8, bounds.min[a]);
  }
  if (f.minor >= 4) {
    storeLE<uint64_t>(h + las::kCount64, count);
    for (int i = 0; i < 15; ++i)
      storeLE<uint64_t>(h + las::kByReturn64 + 8 * i, byReturn[i]);
  }
}

LasRecordWriter::LasRecordWriter(const std::filesystem::path& path, const glm::dvec3& scale,
                                 const glm::dvec3& offset, const RecordFields& fields, LasFlavor flavor)
    : state_(std::make_unique<State>(path, flavor)) {
  State& s = *state_;
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(scale[a]) || scale[a] == 0.0 || !std::isfinite(offset[a]))
      fail(path, "the cloud's scale/offset cannot be written as LAS");
  s.scale = scale;
  s.offset = offset;
  s.fields = fields;
  s.recordLength = las::kRecordSize[static_cast<size_t>(s.f.pointFormat)];
  s.out.emplace(path);
  uint8_t placeholder[las::kHeaderSize14] = {}; // rewritten at commit(), when the counts are known
  s.out->write(placeholder, s.f.headerSize);
}

LasRecordWriter::~LasRecordWriter() = default;

void LasRecordWriter::write(const PointRecord* records, size_t count) {
  State& s = *state_;
  if (s.f.minor < 4 && s.count + count > UINT32_MAX)
    fail(s.path, "more than 4294967295 points do not fit in LAS 1.2; write LAS 1.4");
  for (size_t first = 0; first < count; first += kChunkPoints) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(kChunkPoints, count - first));
    s.encode(records + first, n);
    s.out->write(s.buffer.data(), s.buffer.size());
  }
  s.count += count;
}

uint64_t LasRecordWriter::pointsWritten() const {
  return state_->count;
}

void LasRecordWriter::commit() {
  State& s = *state_;
  uint8_t h[las::kHeaderSize14];
  s.header(h);
  s.out->writeAt(0, h, s.f.headerSize);
  s.out->commit();
}

void writeLas(const std::filesystem::path& path, const PointCloud& cloud, LasFlavor flavor) {
  const FlavorInfo f = flavorInfo(flavor);
  const uint64_t n = cloud.size();
  if (f.minor < 4 && n > UINT32_MAX)
    fail(path, strFormat("%llu points do not fit in LAS 1.2 (at most 4294967295); write LAS 1.4",
                         static_cast<unsigned long long>(n)));
  // Attributes are used only when they match the point count (an empty array means "none").
  RecordFields fields;
  fields.color = cloud.colors.size() == n && n > 0;
  fields.intensity = cloud.intensity.size() == n && n > 0;
  fields.classification = cloud.classification.size() == n && n > 0;
  fields.returnNumber = cloud.returnNumber.size() == n && n > 0;
  fields.pointSourceId = cloud.pointSourceId.size() == n && n > 0;
  LasRecordWriter writer(path, cloud.scale, cloud.offset, fields, flavor);
  std::vector<PointRecord> records(static_cast<size_t>(std::min(n, kChunkPoints)));
  for (uint64_t first = 0; first < n; first += kChunkPoints) {
    const uint64_t count = std::min(kChunkPoints, n - first);
    for (uint64_t k = 0; k < count; ++k) {
      const uint64_t i = first + k;
      PointRecord& r = records[k];
      r.x = cloud.positions[3 * i];
      r.y = cloud.positions[3 * i + 1];
      r.z = cloud.positions[3 * i + 2];
      if (fields.color) {
        // 16-bit channels: v * 257 (= v << 8 | v) maps 0..255 onto the full 0..65535 range.
        const uint32_t c = cloud.colors[i];
        for (int ch = 0; ch < 3; ++ch)
          r.rgb[ch] = static_cast<uint16_t>(((c >> (8 * ch)) & 0xFF) * 257);
      }
      if (fields.intensity) r.intensity = cloud.intensity[i];
      if (fields.classification) r.classification = cloud.classification[i];
      if (fields.returnNumber) r.returnNumber = cloud.returnNumber[i];
      if (fields.pointSourceId) r.pointSourceId = cloud.pointSourceId[i];
    }
    writer.write(records.data(), static_cast<size_t>(count));
  }
  writer.commit();
}

} // namespace pointrast::io
