// Parsing raw LAS point records (ASPRS LAS 1.4 R15, section 2.6) into pointrast's models: blocks of
// records into PointCloud arrays (LAS reader, LAZ reader), one record into a PointRecord (streaming
// sources). Shared so LAS and LAZ files map their records exactly the same way.
#pragma once

#include <algorithm>
#include <climits>
#include <cstdint>

#include "cloud/point_record.h"
#include "io/io_util.h"
#include "io/las/las_format.h"
#include "io/reader.h"

namespace pointrast::io::detail {

struct RecordStats {
  int32_t qmin[3] = {INT32_MAX, INT32_MAX, INT32_MAX};
  int32_t qmax[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  uint16_t colorMax = 0;
};

struct RecordDestination {
  int32_t* positions = nullptr;
  uint32_t* colors = nullptr;    // null: format has no color
  uint16_t* intensity = nullptr; // these four are null unless attributes are kept
  uint8_t* classification = nullptr;
  uint8_t* returnNumber = nullptr;
  uint16_t* pointSourceId = nullptr;
};

// Record layout, R15 section 2.6: X, Y, Z int32 at 0, 4, 8; intensity uint16 at 12; byte 14 holds the
// return number in bits 0-2 (formats 0-5) or bits 0-3 (formats 6-10); the classification is bits 0-4
// of byte 15 (formats 0-5) or all of byte 16 (formats 6-10); the point source id is a uint16 at 18
// (formats 0-5) or 20 (formats 6-10).
template <bool kExtended>
void parseRecords(const uint8_t* src, uint64_t stride, uint64_t count, int rgbOffset, int colorShift,
                  const RecordDestination& dst, RecordStats& stats) {
  RecordStats s;
  for (uint64_t i = 0; i < count; ++i, src += stride) {
    int32_t q[3] = {loadLE<int32_t>(src), loadLE<int32_t>(src + 4), loadLE<int32_t>(src + 8)};
    for (int a = 0; a < 3; ++a) {
      dst.positions[3 * i + a] = q[a];
      s.qmin[a] = std::min(s.qmin[a], q[a]);
      s.qmax[a] = std::max(s.qmax[a], q[a]);
    }
    if (dst.colors) {
      const uint8_t* rgb = src + rgbOffset;
      uint16_t r = loadLE<uint16_t>(rgb), g = loadLE<uint16_t>(rgb + 2), b = loadLE<uint16_t>(rgb + 4);
      s.colorMax = std::max({s.colorMax, r, g, b});
      dst.colors[i] = packRgba((r >> colorShift) & 0xFF, (g >> colorShift) & 0xFF, (b >> colorShift) & 0xFF);
    }
    if (dst.intensity) {
      dst.intensity[i] = loadLE<uint16_t>(src + 12);
      if constexpr (kExtended) {
        dst.returnNumber[i] = src[14] & 0x0F;
        dst.classification[i] = src[16];
        dst.pointSourceId[i] = loadLE<uint16_t>(src + 20);
      } else {
        dst.returnNumber[i] = src[14] & 0x07;
        dst.classification[i] = src[15] & 0x1F;
        dst.pointSourceId[i] = loadLE<uint16_t>(src + 18);
      }
    }
  }
  stats = s;
}

inline RecordDestination offsetBy(const RecordDestination& d, uint64_t i) {
  RecordDestination o;
  o.positions = d.positions + 3 * i;
  if (d.colors) o.colors = d.colors + i;
  if (d.intensity) {
    o.intensity = d.intensity + i;
    o.classification = d.classification + i;
    o.returnNumber = d.returnNumber + i;
    o.pointSourceId = d.pointSourceId + i;
  }
  return o;
}

// One record as a PointRecord; the point source id sits at 18 (formats 0-5) or 20 (formats 6-10).
inline PointRecord toPointRecord(const uint8_t* src, bool extended, int rgbOffset) {
  PointRecord r;
  r.x = loadLE<int32_t>(src);
  r.y = loadLE<int32_t>(src + 4);
  r.z = loadLE<int32_t>(src + 8);
  if (rgbOffset >= 0)
    for (int c = 0; c < 3; ++c)
      r.rgb[c] = loadLE<uint16_t>(src + rgbOffset + 2 * c);
  r.intensity = loadLE<uint16_t>(src + 12);
  if (extended) {
    r.returnNumber = src[14] & 0x0F;
    r.classification = src[16];
    r.pointSourceId = loadLE<uint16_t>(src + 20);
  } else {
    r.returnNumber = src[14] & 0x07;
    r.classification = src[15] & 0x1F;
    r.pointSourceId = loadLE<uint16_t>(src + 18);
  }
  return r;
}

// The fields every LAS point record carries (color where the format has it).
inline RecordFields lasRecordFields(bool hasColor) {
  RecordFields f;
  f.color = hasColor;
  f.intensity = f.returnNumber = f.classification = f.pointSourceId = true;
  return f;
}

// What `info` shows of a LAS or LAZ header ("LAS 1.2, point format 3..." with name "LAS"); colorLo/colorHi:
// the lowest and highest color channel value of the file's records (the bit depth is decided by them).
FileInfo describeLasHeader(const LasHeader& hd, const char* name, uint16_t colorLo, uint16_t colorHi);

} // namespace pointrast::io::detail
