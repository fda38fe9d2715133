#include "io/potree/potree_attributes.h"

namespace pointrast::io::potree {

namespace {

TailAttribute whole(const char* name, const char* type, int size, int offset) {
  TailAttribute a;
  a.name = name;
  a.type = type;
  a.size = a.elementSize = size;
  a.tailOffset = offset;
  return a;
}

TailAttribute bitField(const char* name, int offset, int shift, int bits) {
  TailAttribute a = whole(name, "uint8", 1, offset);
  a.shift = shift;
  a.bits = bits;
  return a;
}

} // namespace

std::vector<TailAttribute> tailAttributes(const PointAttributes& attributes, const AttributeLayout& layout,
                                          const std::vector<detail::ExtraBytesField>& extraBytes) {
  std::vector<TailAttribute> list;
  if (layout.numberOfReturns >= 0)
    list.push_back(whole("number of returns", "uint8", 1, layout.numberOfReturns));
  if (layout.flags >= 0) {
    // The flags byte in the layout of LAS formats 6-10 (point_attributes.h).
    list.push_back(bitField("classification flags", layout.flags, 0, 4));
    list.push_back(bitField("scanner channel", layout.flags, 4, 2));
    list.push_back(bitField("scan direction flag", layout.flags, 6, 1));
    list.push_back(bitField("edge of flight line", layout.flags, 7, 1));
  }
  if (layout.scanAngle >= 0) {
    if (attributes.extendedScanAngle) {
      list.push_back(whole("scan angle", "int16", 2, layout.scanAngle));
    } else {
      // PotreeConverter's type for the rank (an int8 in LAS): the low byte of the tail's int16, which
      // holds the int8's bits, typed uint8.
      list.push_back(whole("scan angle rank", "uint8", 1, layout.scanAngle));
    }
  }
  if (layout.userData >= 0) list.push_back(whole("user data", "uint8", 1, layout.userData));
  if (layout.gpsTime >= 0) list.push_back(whole("gps-time", "double", 8, layout.gpsTime));
  if (layout.nir >= 0) list.push_back(whole("nir", "uint16", 2, layout.nir));
  if (layout.extraBytes >= 0)
    for (const detail::ExtraBytesField& f : extraBytes) {
      TailAttribute a = whole(f.name.c_str(), f.type, f.bytes, layout.extraBytes + f.offset);
      a.description = f.description;
      a.numElements = f.elements;
      a.elementSize = f.elementSize;
      list.push_back(std::move(a));
    }
  return list;
}

} // namespace pointrast::io::potree
