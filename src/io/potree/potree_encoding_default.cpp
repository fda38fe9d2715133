// Potree 2.0 DEFAULT node encoding: each point's attributes one after another, little endian, in the
// order metadata.json lists them (the Potree viewer's DecoderWorker.js reads them so).
#include <algorithm>

#include "io/io_util.h"
#include "io/potree/potree_format.h"

namespace pointrast::io::potree {

using namespace detail;

namespace {

// Byte offset of each record field within a point (-1: no such attribute).
struct FieldOffsets {
  int position = -1, rgb = -1, intensity = -1, returnNumber = -1, classification = -1, pointSourceId = -1;
  bool everyByte = true; // every byte of a point belongs to a record field (no zeros to write)
};

// Bytes a record field fills in a point (0: none).
int fieldBytes(Field field) {
  switch (field) {
  case Field::Position:
    return 12;
  case Field::Rgb:
    return 6;
  case Field::Intensity:
  case Field::PointSourceId:
    return 2;
  case Field::ReturnNumber:
  case Field::Classification:
    return 1;
  case Field::Other:
    break;
  }
  return 0;
}

FieldOffsets fieldOffsets(const Layout& layout) {
  FieldOffsets o;
  int at = 0;
  for (const Attribute& a : layout.attributes) {
    switch (a.field) {
    case Field::Position:
      o.position = at;
      break;
    case Field::Rgb:
      o.rgb = at;
      break;
    case Field::Intensity:
      o.intensity = at;
      break;
    case Field::ReturnNumber:
      o.returnNumber = at;
      break;
    case Field::Classification:
      o.classification = at;
      break;
    case Field::PointSourceId:
      o.pointSourceId = at;
      break;
    case Field::Other:
      break;
    }
    if (fieldBytes(a.field) != a.size) o.everyByte = false;
    at += a.size;
  }
  return o;
}

} // namespace

void encodeDefault(const Layout& layout, const PointRecord* records, size_t n, uint8_t* dst,
                   PotreeValueRanges& ranges) {
  if (n == 0) return; // dst may be null
  const FieldOffsets o = fieldOffsets(layout);
  const size_t stride = static_cast<size_t>(layout.defaultStride);
  if (!o.everyByte) std::memset(dst, 0, n * stride); // attributes without a record field are zeros
  RecordExtremes extremes(ranges);
  for (size_t i = 0; i < n; ++i) {
    const PointRecord& r = records[i];
    extremes.include(r);
    uint8_t* p = dst + i * stride;
    storeLE<int32_t>(p + o.position, r.x);
    storeLE<int32_t>(p + o.position + 4, r.y);
    storeLE<int32_t>(p + o.position + 8, r.z);
    if (o.rgb >= 0)
      for (int c = 0; c < 3; ++c)
        storeLE<uint16_t>(p + o.rgb + 2 * c, r.rgb[c]);
    if (o.intensity >= 0) storeLE<uint16_t>(p + o.intensity, r.intensity);
    if (o.returnNumber >= 0) p[o.returnNumber] = r.returnNumber;
    if (o.classification >= 0) p[o.classification] = r.classification;
    if (o.pointSourceId >= 0) storeLE<uint16_t>(p + o.pointSourceId, r.pointSourceId);
  }
  extremes.into(ranges);
  ranges.count += n;
}

void decodeDefault(const Layout& layout, const uint8_t* src, size_t n, PointRecord* dst) {
  const FieldOffsets o = fieldOffsets(layout);
  const size_t stride = static_cast<size_t>(layout.defaultStride);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = src + i * stride;
    PointRecord r;
    r.x = loadLE<int32_t>(p + o.position);
    r.y = loadLE<int32_t>(p + o.position + 4);
    r.z = loadLE<int32_t>(p + o.position + 8);
    if (o.rgb >= 0)
      for (int c = 0; c < 3; ++c)
        r.rgb[c] = loadLE<uint16_t>(p + o.rgb + 2 * c);
    if (o.intensity >= 0) r.intensity = loadLE<uint16_t>(p + o.intensity);
    if (o.returnNumber >= 0) r.returnNumber = p[o.returnNumber];
    if (o.classification >= 0) r.classification = p[o.classification];
    if (o.pointSourceId >= 0) r.pointSourceId = loadLE<uint16_t>(p + o.pointSourceId);
    dst[i] = r;
  }
}

void encodeDefaultTails(const Layout& layout, const uint8_t* tails, size_t n, uint8_t* dst) {
  const size_t stride = static_cast<size_t>(layout.defaultStride);
  const size_t tailBytes = layout.tail.bytes();
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* t = tails + i * tailBytes;
    uint8_t* p = dst + i * stride;
    for (const TailSlot& s : layout.tailSlots) {
      if (s.bits > 0)
        p[s.pointOffset] = static_cast<uint8_t>((t[s.tailOffset] >> s.shift) & ((1 << s.bits) - 1));
      else
        std::memcpy(p + s.pointOffset, t + s.tailOffset, static_cast<size_t>(s.size));
    }
  }
}

void decodeDefaultTails(const Layout& layout, const uint8_t* src, size_t n, uint8_t* tails) {
  const size_t stride = static_cast<size_t>(layout.defaultStride);
  const size_t tailBytes = layout.tail.bytes();
  std::memset(tails, 0, n * tailBytes);
  for (size_t i = 0; i < n; ++i) {
    uint8_t* t = tails + i * tailBytes;
    const uint8_t* p = src + i * stride;
    for (const TailSlot& s : layout.tailSlots) {
      if (s.bits > 0)
        t[s.tailOffset] =
            static_cast<uint8_t>(t[s.tailOffset] | ((p[s.pointOffset] & ((1 << s.bits) - 1)) << s.shift));
      else
        std::memcpy(t + s.tailOffset, p + s.pointOffset, static_cast<size_t>(s.size));
    }
  }
}

const TailSlot* tailSlotAt(const Layout& layout, int defaultOffset) {
  for (const TailSlot& s : layout.tailSlots)
    if (s.pointOffset == defaultOffset) return &s;
  return nullptr;
}

namespace {

// One element of an attribute's type (Potree 2.0's names) as a double.
double elementValue(const std::string& type, const uint8_t* p) {
  if (type == "int8") return double(int8_t(p[0]));
  if (type == "uint16") return double(loadLE<uint16_t>(p));
  if (type == "int16") return double(loadLE<int16_t>(p));
  if (type == "uint32") return double(loadLE<uint32_t>(p));
  if (type == "int32") return double(loadLE<int32_t>(p));
  if (type == "uint64") return double(loadLE<uint64_t>(p));
  if (type == "int64") return double(loadLE<int64_t>(p));
  if (type == "float") return double(loadLE<float>(p));
  if (type == "double") return loadLE<double>(p);
  return double(p[0]); // uint8, and undocumented bytes
}

} // namespace

void addTailRanges(const Layout& layout, const uint8_t* tails, size_t n, PotreeValueRanges& ranges) {
  const size_t tailBytes = layout.tail.bytes();
  std::vector<double> lo, hi;
  int at = 0;
  for (const Attribute& a : layout.attributes) {
    const TailSlot* slot = a.field == Field::Other ? tailSlotAt(layout, at) : nullptr;
    at += a.size;
    if (!slot) continue;
    for (int e = 0; e < a.numElements; ++e) {
      double mn = 0, mx = 0;
      for (size_t i = 0; i < n; ++i) {
        const uint8_t* t = tails + i * tailBytes;
        const double v =
            slot->bits > 0
                ? double((t[slot->tailOffset] >> slot->shift) & ((1 << slot->bits) - 1))
                : elementValue(a.type, t + slot->tailOffset + size_t(e) * size_t(std::max(a.elementSize, 1)));
        mn = i == 0 || v < mn ? v : mn;
        mx = i == 0 || v > mx ? v : mx;
      }
      lo.push_back(mn);
      hi.push_back(mx);
    }
  }
  if (n == 0) return;
  PotreeValueRanges node;
  node.tailMin = std::move(lo);
  node.tailMax = std::move(hi);
  if (ranges.tailMin.empty()) {
    ranges.tailMin = std::move(node.tailMin);
    ranges.tailMax = std::move(node.tailMax);
  } else {
    for (size_t k = 0; k < ranges.tailMin.size() && k < node.tailMin.size(); ++k) {
      ranges.tailMin[k] = std::min(ranges.tailMin[k], node.tailMin[k]);
      ranges.tailMax[k] = std::max(ranges.tailMax[k], node.tailMax[k]);
    }
  }
}

} // namespace pointrast::io::potree
