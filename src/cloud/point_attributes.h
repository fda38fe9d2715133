// The attributes of a point beyond PointRecord's (GPS time, number of returns, scan flags, scan angle,
// user data, NIR, extra bytes), as a compact tail of bytes that travels beside a record. Which attributes
// a tail holds is chosen from what the inputs have, so a cloud of positions and colors carries an empty
// tail and pays nothing for GPS times it does not have.
//
// Tail layout (AttributeLayout): present fields only, widest first so that each lies at a multiple of its
// size when the tail does; values are stored little endian, as their LAS fields are:
//   gpsTime          float64  GPS time
//   scanAngle        int16    the source's own value: degrees (rank, formats 0-5) or 0.006 degree units
//                             (formats 6-10), see PointAttributes::extendedScanAngle
//   nir              uint16   near infrared
//   numberOfReturns  uint8
//   flags            uint8    as byte 15 of LAS formats 6-10: bits 0-3 classification flags (synthetic,
//                             key-point, withheld, overlap), bits 4-5 scanner channel, bit 6 scan
//                             direction, bit 7 edge of flight line
//   userData         uint8
//   extra bytes      extraBytes bytes, opaque (their meaning is in the source's descriptors)
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

namespace pointrast {

struct PointAttributes {
  bool gpsTime = false;
  bool scanAngle = false;
  bool nir = false;
  bool numberOfReturns = false;
  bool flags = false;
  bool userData = false;
  bool extendedScanAngle = false; // scanAngle in 0.006 degree units (LAS formats 6-10), else degrees
  uint16_t extraBytes = 0;

  bool any() const {
    return gpsTime || scanAngle || nir || numberOfReturns || flags || userData || extraBytes > 0;
  }
  friend bool operator==(const PointAttributes&, const PointAttributes&) = default;
};

// Byte offsets of the fields inside a tail (-1: absent) and the tail's size.
struct AttributeLayout {
  int gpsTime = -1;
  int scanAngle = -1;
  int nir = -1;
  int numberOfReturns = -1;
  int flags = -1;
  int userData = -1;
  int extraBytes = -1;
  uint32_t bytes = 0;
};

AttributeLayout attributeLayout(const PointAttributes& attributes);

// The attributes that hold both a and b without loss, or false in `ok` where they cannot be merged into one
// tail: different extra bytes (their descriptors are the caller's to compare) or scan angles in different
// units (one would be rounded).
PointAttributes mergeAttributes(const PointAttributes& a, const PointAttributes& b, bool& ok);

// What the tails of a set of points hold and where they came from: the attributes, their layout, and
// for LAS inputs the point format and extra bytes descriptors (the payloads of the extra bytes VLRs,
// 192 bytes each), so an export can write the records back in their own format.
struct TailFormat {
  PointAttributes attributes;
  AttributeLayout layout;
  int lasPointFormat = -1; // -1: not from LAS records
  std::vector<uint8_t> extraBytesDescriptors;

  uint32_t bytes() const { return layout.bytes; }
};

// Field access in a tail; the field must be present (offset >= 0: asserted by the caller's layout).
template <class T> inline T loadTail(const uint8_t* tail, int offset) {
  T v;
  std::memcpy(&v, tail + offset, sizeof v);
  return v;
}
template <class T> inline void storeTail(uint8_t* tail, int offset, T v) {
  std::memcpy(tail + offset, &v, sizeof v);
}

} // namespace pointrast
