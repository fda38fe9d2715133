#include "io/las/las_attributes.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "io/io_util.h"
#include "io/las/las_format.h"

namespace pointrast::io::detail {

namespace {

// R15 section 2.6: formats 0-5 hold the scan angle rank as int8 degrees at 16; formats 6-10 an int16 in
// 0.006 degree units at 18.
constexpr double kAngleUnit = 0.006;

bool hasGpsTime(int f) {
  return f == 1 || f >= 3;
}
bool hasNir(int f) {
  return f == 8 || f == 10;
}
constexpr int kNirOffset = 36; // formats 8 and 10, after RGB at 30

int16_t convertAngle(int16_t value, bool fromExtended, bool toExtended) {
  if (fromExtended == toExtended) return value;
  if (toExtended)
    return static_cast<int16_t>(std::clamp<long>(std::lround(value / kAngleUnit), -32768, 32767));
  return static_cast<int16_t>(std::clamp<long>(std::lround(value * kAngleUnit), -128, 127));
}

// R15 Table 25: data types 1-10, one element each; 11-20 and 21-30 repeat them two and three times.
struct ElementType {
  const char* name;
  int size;
};
constexpr ElementType kElementTypes[10] = {{"uint8", 1},  {"int8", 1},  {"uint16", 2}, {"int16", 2},
                                           {"uint32", 4}, {"int32", 4}, {"uint64", 8}, {"int64", 8},
                                           {"float", 4},  {"double", 8}};
constexpr size_t kDescriptorBytes = 192;

std::string fixedString(const uint8_t* p, size_t n) {
  size_t len = 0;
  while (len < n && p[len] != 0)
    ++len;
  return std::string(reinterpret_cast<const char*>(p), len);
}

} // namespace

std::vector<ExtraBytesField> parseExtraBytes(const std::vector<uint8_t>& descriptors, uint16_t extraBytes,
                                             const std::string& where) {
  if (descriptors.size() % kDescriptorBytes != 0)
    throw InputError(where + ": an extra bytes description is not a whole number of 192-byte descriptors");
  std::vector<ExtraBytesField> fields;
  uint32_t at = 0;
  for (size_t k = 0; k < descriptors.size() / kDescriptorBytes; ++k) {
    const uint8_t* d = descriptors.data() + k * kDescriptorBytes;
    ExtraBytesField f;
    f.dataType = d[2];
    f.options = d[3];
    f.name = fixedString(d + 4, 32);
    f.description = fixedString(d + 160, 32);
    if (f.dataType == 0) {
      f.elements = f.options;
      f.elementSize = 1;
    } else if (f.dataType <= 30) {
      const ElementType& t = kElementTypes[(f.dataType - 1) % 10];
      f.elements = 1 + (f.dataType - 1) / 10;
      f.elementSize = t.size;
      f.type = t.name;
    } else {
      throw InputError(strFormat("%s: extra bytes field \"%s\" has the unknown data type %d", where.c_str(),
                                 f.name.c_str(), int(f.dataType)));
    }
    for (int e = 0; e < 3; ++e) {
      if (f.dataType != 0 && (f.options & 0x08)) f.scale[e] = loadLE<double>(d + 112 + 8 * e);
      if (f.dataType != 0 && (f.options & 0x10)) f.valueOffset[e] = loadLE<double>(d + 136 + 8 * e);
    }
    f.bytes = static_cast<uint16_t>(f.elements * f.elementSize);
    f.offset = static_cast<uint16_t>(std::min<uint32_t>(at, 0xFFFF));
    at += f.bytes;
    if (at > extraBytes)
      throw InputError(strFormat("%s: the extra bytes fields take %u bytes, more than the %u each record has",
                                 where.c_str(), unsigned(at), unsigned(extraBytes)));
    if (f.bytes > 0) fields.push_back(std::move(f));
  }
  if (at < extraBytes) {
    ExtraBytesField rest;
    rest.name = "extra bytes";
    rest.offset = static_cast<uint16_t>(at);
    rest.elements = extraBytes - int(at);
    rest.bytes = static_cast<uint16_t>(rest.elements);
    fields.push_back(std::move(rest));
  }
  return fields;
}

PointAttributes lasAttributes(int pointFormat, uint16_t extraBytes) {
  PointAttributes a;
  a.gpsTime = hasGpsTime(pointFormat);
  a.scanAngle = a.numberOfReturns = a.flags = a.userData = true;
  a.extendedScanAngle = las::isExtended(pointFormat);
  a.nir = hasNir(pointFormat);
  a.extraBytes = extraBytes;
  return a;
}

void packLasAttributes(const uint8_t* record, int pointFormat, const AttributeLayout& layout,
                       const PointAttributes& attributes, uint8_t* tail) {
  std::memset(tail, 0, layout.bytes);
  const bool extended = las::isExtended(pointFormat);
  int16_t angle;
  uint8_t returns, flags;
  if (extended) {
    returns = record[14] >> 4;
    flags = record[15];
    angle = loadLE<int16_t>(record + 18);
  } else {
    returns = (record[14] >> 3) & 0x07;
    // Synthetic, key-point, withheld (bits 5-7 of byte 15); scan direction and edge (bits 6-7 of 14).
    flags = static_cast<uint8_t>((record[15] >> 5) | (record[14] & 0xC0));
    angle = static_cast<int8_t>(record[16]);
  }
  if (layout.numberOfReturns >= 0) tail[layout.numberOfReturns] = returns;
  if (layout.flags >= 0) tail[layout.flags] = flags;
  if (layout.userData >= 0) tail[layout.userData] = record[17];
  if (layout.scanAngle >= 0)
    storeTail<int16_t>(tail, layout.scanAngle, convertAngle(angle, extended, attributes.extendedScanAngle));
  if (layout.gpsTime >= 0 && hasGpsTime(pointFormat))
    std::memcpy(tail + layout.gpsTime, record + (extended ? 22 : 20), 8);
  if (layout.nir >= 0 && hasNir(pointFormat)) std::memcpy(tail + layout.nir, record + kNirOffset, 2);
  if (layout.extraBytes >= 0)
    std::memcpy(tail + layout.extraBytes, record + las::kRecordSize[static_cast<size_t>(pointFormat)],
                attributes.extraBytes);
}

void unpackLasAttributes(const uint8_t* tail, const AttributeLayout& layout,
                         const PointAttributes& attributes, int pointFormat, uint8_t* record) {
  const bool extended = las::isExtended(pointFormat);
  const uint8_t returns = layout.numberOfReturns >= 0 ? tail[layout.numberOfReturns] : 0;
  const uint8_t flags = layout.flags >= 0 ? tail[layout.flags] : 0;
  const int16_t angle = layout.scanAngle >= 0 ? convertAngle(loadTail<int16_t>(tail, layout.scanAngle),
                                                             attributes.extendedScanAngle, extended)
                                              : int16_t(0);
  // Without a number of returns in the tail, the record's own bits stay.
  const bool hasReturns = layout.numberOfReturns >= 0;
  if (extended) {
    record[14] = static_cast<uint8_t>(hasReturns ? (record[14] & 0x0F) | (std::min<uint8_t>(returns, 15) << 4)
                                                 : record[14]);
    record[15] = flags;
    storeLE<int16_t>(record + 18, angle);
  } else {
    record[14] = static_cast<uint8_t>(
        (hasReturns ? (record[14] & 0x07) | (std::min<uint8_t>(returns, 7) << 3) : record[14] & 0x3F) |
        (flags & 0xC0));
    record[15] = static_cast<uint8_t>((record[15] & 0x1F) | ((flags & 0x07) << 5));
    record[16] = static_cast<uint8_t>(static_cast<int8_t>(angle));
  }
  if (layout.userData >= 0) record[17] = tail[layout.userData];
  if (layout.gpsTime >= 0 && hasGpsTime(pointFormat))
    std::memcpy(record + (extended ? 22 : 20), tail + layout.gpsTime, 8);
  if (layout.nir >= 0 && hasNir(pointFormat)) std::memcpy(record + kNirOffset, tail + layout.nir, 2);
  if (layout.extraBytes >= 0)
    std::memcpy(record + las::kRecordSize[static_cast<size_t>(pointFormat)], tail + layout.extraBytes,
                attributes.extraBytes);
}

TailFormat lasTailFormat(const InputFile& file, const LasHeader& header) {
  TailFormat t;
  const uint16_t base = las::kRecordSize[static_cast<size_t>(header.pointFormat)];
  const uint16_t extra = header.recordLength > base ? uint16_t(header.recordLength - base) : uint16_t(0);
  t.attributes = lasAttributes(header.pointFormat, extra);
  t.layout = attributeLayout(t.attributes);
  t.lasPointFormat = header.pointFormat;
  if (extra > 0) {
    for (const LasVlr& v : header.vlrs)
      if (v.userId == "LASF_Spec" && v.recordId == 4) {
        const size_t at = t.extraBytesDescriptors.size();
        t.extraBytesDescriptors.resize(at + v.length);
        file.readAt(v.dataOffset, t.extraBytesDescriptors.data() + at, v.length);
      }
    try {
      parseExtraBytes(t.extraBytesDescriptors, extra, "");
    } catch (const InputError&) {
      t.extraBytesDescriptors.clear();
    }
  }
  return t;
}

void packLasTails(const uint8_t* records, uint64_t stride, uint64_t count, int pointFormat,
                  uint16_t extraBytes, const TailFormat& tail, uint8_t* tails) {
  const uint32_t bytes = tail.bytes();
  PointAttributes own = tail.attributes;
  own.extraBytes = std::min(own.extraBytes, extraBytes);
  for (uint64_t i = 0; i < count; ++i)
    packLasAttributes(records + i * stride, pointFormat, tail.layout, own, tails + i * bytes);
}

} // namespace pointrast::io::detail
