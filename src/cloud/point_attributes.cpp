#include "cloud/point_attributes.h"

namespace pointrast {

AttributeLayout attributeLayout(const PointAttributes& a) {
  AttributeLayout l;
  int at = 0;
  auto place = [&](bool present, int& offset, int size) {
    if (!present) return;
    offset = at;
    at += size;
  };
  place(a.gpsTime, l.gpsTime, 8);
  place(a.scanAngle, l.scanAngle, 2);
  place(a.nir, l.nir, 2);
  place(a.numberOfReturns, l.numberOfReturns, 1);
  place(a.flags, l.flags, 1);
  place(a.userData, l.userData, 1);
  place(a.extraBytes > 0, l.extraBytes, a.extraBytes);
  l.bytes = static_cast<uint32_t>(at);
  return l;
}

PointAttributes mergeAttributes(const PointAttributes& a, const PointAttributes& b, bool& ok) {
  PointAttributes m;
  m.gpsTime = a.gpsTime || b.gpsTime;
  m.scanAngle = a.scanAngle || b.scanAngle;
  m.nir = a.nir || b.nir;
  m.numberOfReturns = a.numberOfReturns || b.numberOfReturns;
  m.flags = a.flags || b.flags;
  m.userData = a.userData || b.userData;
  ok = true;
  if (a.scanAngle && b.scanAngle && a.extendedScanAngle != b.extendedScanAngle) ok = false;
  m.extendedScanAngle = a.scanAngle ? a.extendedScanAngle : b.extendedScanAngle;
  if (a.extraBytes && b.extraBytes && a.extraBytes != b.extraBytes) ok = false;
  m.extraBytes = a.extraBytes ? a.extraBytes : b.extraBytes;
  return m;
}

} // namespace pointrast
