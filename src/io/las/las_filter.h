// Point filters on raw LAS point records (ASPRS LAS 1.4 R15, section 2.6): the fields a PointFilter reads,
// straight from the record bytes, legacy (formats 0-5) and extended (6-10) layouts alike.
#pragma once

#include <cstdint>

#include "cloud/point_filter.h"
#include "io/io_util.h"
#include "io/las/las_format.h"

namespace pointrast::io::detail {

// Byte offset of the GPS time double, or -1: formats 1, 3, 4, 5 at 20; formats 6-10 at 22.
inline int lasGpsOffset(int pointFormat) {
  if (pointFormat >= 6) return 22;
  return pointFormat == 1 || pointFormat >= 3 ? 20 : -1;
}

// What a LAS point format holds of what a filter reads: everything but GPS time in formats 0 and 2.
inline FilterNeeds lasFilterFields(int pointFormat) {
  FilterNeeds has;
  has.classification = has.returnNumber = has.numberOfReturns = has.intensity = has.pointSourceId = true;
  has.gpsTime = lasGpsOffset(pointFormat) >= 0;
  return has;
}

// Byte 14 holds the return number in bits 0-2 and the number of returns in bits 3-5 (formats 0-5) or
// 4 bits each (6-10); the class is bits 0-4 of byte 15 (0-5) or byte 16 (6-10); the point source id a
// uint16 at 18 (0-5) or 20 (6-10).
inline FilterPoint lasFilterPoint(const uint8_t* r, int pointFormat, const glm::dvec3& scale,
                                  const glm::dvec3& offset) {
  FilterPoint p;
  p.position =
      glm::dvec3(loadLE<int32_t>(r), loadLE<int32_t>(r + 4), loadLE<int32_t>(r + 8)) * scale + offset;
  p.intensity = loadLE<uint16_t>(r + 12);
  if (las::isExtended(pointFormat)) {
    p.returnNumber = r[14] & 0x0F;
    p.numberOfReturns = r[14] >> 4;
    p.classification = r[16];
    p.pointSourceId = loadLE<uint16_t>(r + 20);
  } else {
    p.returnNumber = r[14] & 0x07;
    p.numberOfReturns = (r[14] >> 3) & 0x07;
    p.classification = r[15] & 0x1F;
    p.pointSourceId = loadLE<uint16_t>(r + 18);
  }
  const int gps = lasGpsOffset(pointFormat);
  if (gps >= 0) p.gpsTime = loadLE<double>(r + gps);
  return p;
}

} // namespace pointrast::io::detail
