#include "render/lod/node_encoding.h"

#include <algorithm>
#include <cassert>

#include "cloud/batch.h"
#include "cloud/batch_words.h"
#include "gpu/shared_types.h"
#include "render/lod/selection.h"

namespace pointrast::lod {

NodeEncoder::NodeEncoder(const OctreeMetadata& metadata, const std::vector<PointRecord>& sample)
    : metadata_(metadata) {
  uint16_t colorMax = metadata.fields.colorMax;
  if (metadata.fields.color && colorMax == 0)
    for (const PointRecord& r : sample)
      colorMax = std::max({colorMax, r.rgb[0], r.rgb[1], r.rgb[2]});
  colorShift_ = colorMax > 255 ? 8 : 0;
  PointCloud cloud = cloudOf(sample);
  computeBounds(cloud);
  mode_ = displayColorMode(cloud);
}

PointCloud NodeEncoder::cloudOf(const std::vector<PointRecord>& records) const {
  PointCloud cloud;
  cloud.scale = metadata_.scale;
  cloud.offset = metadata_.offset;
  cloud.source = metadata_.source;
  appendRecords(cloud, records.data(), records.size(), metadata_.fields, colorShift_);
  return cloud;
}

Bounds NodeEncoder::encode(const std::vector<PointRecord>& records, std::span<uint8_t* const> pages) const {
  assert(pages.size() == pagesOf(records.size()));
  const PointCloud cloud = cloudOf(records);
  // Bounds in one thread: readers encode nodes in parallel already.
  const Bounds bounds = makeBatch(cloud, 0, uint32_t(records.size())).bounds;
  for (size_t k = 0; k < pages.size(); ++k) {
    const uint64_t first = k * shared::kLodPagePoints;
    Batch batch;
    batch.first = first;
    batch.count = uint32_t(std::min<uint64_t>(shared::kLodPagePoints, records.size() - first));
    batch.bounds = bounds; // the node's: every page of a node decodes in the same box
    auto* section = reinterpret_cast<uint32_t*>(pages[k]);
    constexpr uint32_t n = shared::kLodPagePoints;
    encodeBatchWords(section, section + n, section + 2 * n, cloud, batch);
    displayColors(section + 3 * n, cloud, batch.first, batch.count, mode_);
    // A page's last group of four is read whole by 128-bit loads: its padding words are zeros, not stale.
    for (uint32_t i = batch.count; i < ((batch.count + 3) & ~3u); ++i)
      section[i] = section[n + i] = section[2 * n + i] = section[3 * n + i] = 0;
  }
  return bounds;
}

} // namespace pointrast::lod
