// The Potree writer's value ranges (metadata.json's attribute minima and maxima): computed in vector
// lanes that each cover one record field, checked field by field against plain minima and maxima, through
// PotreeValueRanges::add, through the DEFAULT encoder, and in metadata.json.
#include <random>

#include <gtest/gtest.h>

#include "io/io_test_util.h"
#include "io/potree/potree_format.h"

namespace {

using namespace pointrast;
using namespace pointrast::io;

// Records whose fields each take values over their whole type, with the type's extremes among them.
std::vector<PointRecord> hostileRecords(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  auto any = [&](auto lo, auto hi) {
    return static_cast<decltype(lo)>(std::uniform_int_distribution<int64_t>(lo, hi)(rng));
  };
  std::vector<PointRecord> out(n);
  for (PointRecord& r : out) {
    r.x = any(INT32_MIN, INT32_MAX);
    r.y = any(INT32_MIN, INT32_MAX);
    r.z = any(INT32_MIN, INT32_MAX);
    for (uint16_t& c : r.rgb)
      c = any(uint16_t(0), UINT16_MAX);
    r.intensity = any(uint16_t(0), UINT16_MAX);
    r.returnNumber = any(uint8_t(0), UINT8_MAX);
    r.classification = any(uint8_t(0), UINT8_MAX);
    r.pointSourceId = any(uint16_t(0), UINT16_MAX);
  }
  return out;
}

// The ranges as written out field by field.
PotreeValueRanges plainRanges(const std::vector<PointRecord>& records) {
  PotreeValueRanges r;
  for (const PointRecord& p : records) {
    const int32_t q[3] = {p.x, p.y, p.z};
    for (int a = 0; a < 3; ++a) {
      r.positionMin[a] = std::min(r.positionMin[a], q[a]);
      r.positionMax[a] = std::max(r.positionMax[a], q[a]);
      r.rgbMin[a] = std::min(r.rgbMin[a], p.rgb[a]);
      r.rgbMax[a] = std::max(r.rgbMax[a], p.rgb[a]);
    }
    r.intensityMin = std::min(r.intensityMin, p.intensity);
    r.intensityMax = std::max(r.intensityMax, p.intensity);
    r.returnMin = std::min(r.returnMin, p.returnNumber);
    r.returnMax = std::max(r.returnMax, p.returnNumber);
    r.classMin = std::min(r.classMin, p.classification);
    r.classMax = std::max(r.classMax, p.classification);
    r.sourceMin = std::min(r.sourceMin, p.pointSourceId);
    r.sourceMax = std::max(r.sourceMax, p.pointSourceId);
  }
  r.count = records.size();
  return r;
}

void expectSameRanges(const PotreeValueRanges& a, const PotreeValueRanges& b) {
  EXPECT_EQ(a.count, b.count);
  EXPECT_EQ(a.positionMin, b.positionMin);
  EXPECT_EQ(a.positionMax, b.positionMax);
  EXPECT_EQ(a.rgbMin, b.rgbMin);
  EXPECT_EQ(a.rgbMax, b.rgbMax);
  EXPECT_EQ(a.intensityMin, b.intensityMin);
  EXPECT_EQ(a.intensityMax, b.intensityMax);
  EXPECT_EQ(a.returnMin, b.returnMin);
  EXPECT_EQ(a.returnMax, b.returnMax);
  EXPECT_EQ(a.classMin, b.classMin);
  EXPECT_EQ(a.classMax, b.classMax);
  EXPECT_EQ(a.sourceMin, b.sourceMin);
  EXPECT_EQ(a.sourceMax, b.sourceMax);
}

TEST(PotreeRanges, AddMatchesPlainExtremesFieldByField) {
  const std::vector<PointRecord> records = hostileRecords(5'000, 7);
  PotreeValueRanges ranges;
  // In uneven parts: each add() starts from the extremes so far.
  ranges.add(records.data(), 1);
  ranges.add(records.data() + 1, 1'234);
  ranges.add(records.data() + 1'235, records.size() - 1'235);
  expectSameRanges(ranges, plainRanges(records));
}

// Each field moved alone: a lane that leaked into a neighbour's would move that neighbour's extreme.
TEST(PotreeRanges, EachFieldMovesOnlyItsOwnExtremes) {
  PointRecord middle;
  middle.x = middle.y = middle.z = 1000;
  middle.rgb[0] = middle.rgb[1] = middle.rgb[2] = 1000;
  middle.intensity = middle.pointSourceId = 1000;
  middle.returnNumber = middle.classification = 100;
  for (int field = 0; field < 11; ++field)
    for (const bool high : {false, true}) {
      std::vector<PointRecord> records{middle, middle};
      PointRecord& r = records[1];
      switch (field) {
      case 0:
        r.x = high ? INT32_MAX : INT32_MIN;
        break;
      case 1:
        r.y = high ? INT32_MAX : INT32_MIN;
        break;
      case 2:
        r.z = high ? INT32_MAX : INT32_MIN;
        break;
      case 3:
      case 4:
      case 5:
        r.rgb[field - 3] = high ? UINT16_MAX : 0;
        break;
      case 6:
        r.intensity = high ? UINT16_MAX : 0;
        break;
      case 7:
        r.returnNumber = high ? UINT8_MAX : 0;
        break;
      case 8:
        r.classification = high ? UINT8_MAX : 0;
        break;
      case 9:
        r.pointSourceId = high ? UINT16_MAX : 0;
        break;
      default:
        r.x = high ? -1 : 0x7fff0000;
        break; // bytes that are uint16 and uint8 lanes elsewhere
      }
      PotreeValueRanges ranges;
      ranges.add(records.data(), records.size());
      SCOPED_TRACE(testing::Message() << "field " << field << (high ? " high" : " low"));
      expectSameRanges(ranges, plainRanges(records));
    }
}

TEST(PotreeRanges, DefaultEncoderAddsTheSameRangesAndRoundTrips) {
  const std::vector<PointRecord> records = hostileRecords(3'000, 11);
  RecordFields fields;
  fields.color = fields.intensity = fields.returnNumber = fields.classification = fields.pointSourceId = true;
  const potree::Layout layout = potree::writerLayout(fields);
  ASSERT_EQ(layout.defaultStride, 24u);
  std::vector<uint8_t> bytes(records.size() * layout.defaultStride);
  PotreeValueRanges ranges;
  potree::encodeDefault(layout, records.data(), 1'000, bytes.data(), ranges);
  potree::encodeDefault(layout, records.data() + 1'000, 2'000, bytes.data() + 1'000 * 24, ranges);
  expectSameRanges(ranges, plainRanges(records));
  std::vector<PointRecord> decoded(records.size());
  potree::decodeDefault(layout, bytes.data(), records.size(), decoded.data());
  EXPECT_EQ(decoded, records);
}

potree::Attribute attribute(const char* name, const char* type, int elements, int elementSize) {
  potree::Attribute a;
  a.name = name;
  a.type = type;
  a.numElements = elements;
  a.elementSize = elementSize;
  a.size = elements * elementSize;
  return a;
}

// A layout with a gap (an attribute without a record field): those bytes are written as zeros.
TEST(PotreeRanges, DefaultEncoderZeroesBytesWithoutAField) {
  const potree::Layout layout =
      potree::makeLayout({attribute("position", "int32", 3, 4), attribute("gps-time", "double", 1, 8),
                          attribute("intensity", "uint16", 1, 2)});
  ASSERT_EQ(layout.defaultStride, 22u);
  const std::vector<PointRecord> records = hostileRecords(50, 3);
  std::vector<uint8_t> bytes(records.size() * 22, 0xAB);
  PotreeValueRanges ranges;
  potree::encodeDefault(layout, records.data(), records.size(), bytes.data(), ranges);
  for (size_t i = 0; i < records.size(); ++i)
    for (size_t b = 12; b < 20; ++b)
      ASSERT_EQ(bytes[i * 22 + b], 0) << "point " << i << " byte " << b;
  EXPECT_EQ(ranges.count, records.size());
}

} // namespace
