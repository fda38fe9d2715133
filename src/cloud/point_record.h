// One point with the attributes pointrast keeps, as every streaming source (LAS, LAZ, COPC, EPT,
// Potree 2.0 nodes) delivers it and as the octree builder moves it around. Positions stay the integers of
// their source (world = q * scale + offset of the source that produced the record), colors stay at the
// bit depth of the source (8- or 16-bit values in 16-bit fields, as LAS stores them), so nothing is
// rounded on the way from an input file into an octree and back.
//
// 24 bytes, no padding the compiler adds: 3 x 4 position, 3 x 2 color, 2 intensity, 1 return number,
// 1 classification, 2 point source id (the last two bytes that would otherwise be padding).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cloud/cloud.h"

namespace pointrast {

struct PointRecord {
  int32_t x = 0, y = 0, z = 0;     // quantized position
  uint16_t rgb[3] = {0, 0, 0};     // as stored by the source (0 when it has no color)
  uint16_t intensity = 0;          // 0 when the source has none
  uint8_t returnNumber = 0;        // 0 when the source has none
  uint8_t classification = 0;      // 0 when the source has none
  uint16_t pointSourceId = 0;      // 0 when the source has none

  friend bool operator==(const PointRecord&, const PointRecord&) = default;
};
static_assert(sizeof(PointRecord) == 24, "PointRecord is 24 bytes, without padding");
static_assert(offsetof(PointRecord, rgb) == 12 && offsetof(PointRecord, intensity) == 18 &&
              offsetof(PointRecord, returnNumber) == 20 && offsetof(PointRecord, classification) == 21 &&
              offsetof(PointRecord, pointSourceId) == 22);

// Which fields of PointRecord carry data from the source (the others are zero).
struct RecordFields {
  bool color = false;
  bool intensity = false;
  bool returnNumber = false;
  bool classification = false;
  bool pointSourceId = false;
  // Largest color channel value of the source when known (0: unknown). Above 255 means 16-bit colors;
  // a reader that cannot know it before reading every point leaves it 0 and consumers decide per block.
  uint16_t colorMax = 0;
};

} // namespace pointrast

namespace pointrast {

// Appends records to a PointCloud whose scale/offset the caller has set to the records' source.
// colorShift: 8 for 16-bit colors (RecordFields::colorMax > 255), 0 for 8-bit. Arrays the fields do not
// carry are left alone (they must be empty, or the caller keeps them the same length).
void appendRecords(PointCloud& cloud, const PointRecord* records, size_t count, const RecordFields& fields,
                   int colorShift);
// The same into points [first, first + count) of a cloud whose arrays the caller has already sized for
// the fields, so that several threads can fill disjoint ranges at once.
void storeRecords(PointCloud& cloud, uint64_t first, const PointRecord* records, size_t count,
                  const RecordFields& fields, int colorShift);

// The record fields a cloud carries (its colors are 8-bit: colorMax 255 when it has any).
RecordFields recordFieldsOf(const PointCloud& cloud);
// The inverse of storeRecords with colorShift 0: points [first, first + count) of a cloud as records, in
// the cloud's scale/offset, for building an octree from points in memory. Fields the cloud lacks are 0.
void loadRecords(const PointCloud& cloud, uint64_t first, size_t count, PointRecord* out);

} // namespace pointrast
