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

RecordFields recordFieldsOf(const PointCloud& cloud) {
  RecordFields f;
  f.color = cloud.hasColor();
  f.colorMax = f.color ? 255 : 0;
  f.intensity = !cloud.intensity.empty();
  f.classification = !cloud.classification.empty();
  f.returnNumber = !cloud.returnNumber.empty();
  f.pointSourceId = !cloud.pointSourceId.empty();
  return f;
}

void loadRecords(const PointCloud& cloud, uint64_t first, size_t count, PointRecord* out) {
  const RecordFields f = recordFieldsOf(cloud);
  for (size_t i = 0; i < count; ++i) {
    const uint64_t k = first + i;
    PointRecord r;
    r.x = cloud.positions[3 * k];
    r.y = cloud.positions[3 * k + 1];
    r.z = cloud.positions[3 * k + 2];
    if (f.color)
      for (int c = 0; c < 3; ++c)
        r.rgb[c] = uint16_t((cloud.colors[k] >> (8 * c)) & 0xFF);
    if (f.intensity) r.intensity = cloud.intensity[k];
    if (f.classification) r.classification = cloud.classification[k];
    if (f.returnNumber) r.returnNumber = cloud.returnNumber[k];
    if (f.pointSourceId) r.pointSourceId = cloud.pointSourceId[k];
    out[i] = r;
  }
}

} // namespace pointrast
