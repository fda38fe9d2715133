#include "cloud/point_record.h"

#include <algorithm>

namespace pointrast {

void appendRecords(PointCloud& cloud, const PointRecord* records, size_t count, const RecordFields& fields,
                   int colorShift) {
  const uint64_t first = cloud.size();
  cloud.positions.resize(3 * (first + count));
  if (fields.color) cloud.colors.resize(first + count);
  if (fields.intensity) cloud.intensity.resize(first + count);
  if (fields.classification) cloud.classification.resize(first + count);
  if (fields.returnNumber) cloud.returnNumber.resize(first + count);
  if (fields.pointSourceId) cloud.pointSourceId.resize(first + count);
  storeRecords(cloud, first, records, count, fields, colorShift);
}

void storeRecords(PointCloud& cloud, uint64_t first, const PointRecord* records, size_t count,
                  const RecordFields& fields, int colorShift) {
  for (size_t i = 0; i < count; ++i) {
    const PointRecord& r = records[i];
    int32_t* p = &cloud.positions[3 * (first + i)];
    p[0] = r.x;
    p[1] = r.y;
    p[2] = r.z;
    if (fields.color)
      cloud.colors[first + i] = packRgba((r.rgb[0] >> colorShift) & 0xFF, (r.rgb[1] >> colorShift) & 0xFF,
                                         (r.rgb[2] >> colorShift) & 0xFF);
    if (fields.intensity) cloud.intensity[first + i] = r.intensity;
    if (fields.classification) cloud.classification[first + i] = r.classification;
    if (fields.returnNumber) cloud.returnNumber[first + i] = r.returnNumber;
    if (fields.pointSourceId) cloud.pointSourceId[first + i] = r.pointSourceId;
  }
}

} // namespace pointrast
