#include "cloud/octree_cloud.h"

#include <algorithm>
#include <optional>

#include "base/error.h"
#include "base/parallel.h"
#include "base/progress.h"

namespace pointrast::lod {

namespace {

uint16_t largestChannel(const std::vector<PointRecord>& records) {
  uint16_t m = 0;
  for (const PointRecord& r : records)
    m = std::max({m, r.rgb[0], r.rgb[1], r.rgb[2]});
  return m;
}

template <class T> void moveRange(std::vector<T>& v, uint64_t from, uint64_t to, uint64_t n, uint64_t per) {
  if (v.empty() || from == to) return;
  std::copy(v.begin() + ptrdiff_t(per * from), v.begin() + ptrdiff_t(per * (from + n)),
            v.begin() + ptrdiff_t(per * to));
}

// Closes the gaps of nodes that delivered fewer points than listed (a source may find a listed count to
// be stale once it reads the node: PotreeConverter's emptied inner nodes behind a proxy).
void compact(PointCloud& cloud, const std::vector<uint64_t>& first, const std::vector<uint64_t>& actual) {
  uint64_t cursor = 0;
  for (size_t b = 0; b < actual.size(); ++b) {
    moveRange(cloud.positions, first[b], cursor, actual[b], 3);
    moveRange(cloud.colors, first[b], cursor, actual[b], 1);
    moveRange(cloud.intensity, first[b], cursor, actual[b], 1);
    moveRange(cloud.classification, first[b], cursor, actual[b], 1);
    moveRange(cloud.returnNumber, first[b], cursor, actual[b], 1);
    moveRange(cloud.pointSourceId, first[b], cursor, actual[b], 1);
    cursor += actual[b];
  }
  cloud.positions.resize(3 * cursor);
  auto shrink = [&](auto& v) {
    if (!v.empty()) v.resize(cursor);
  };
  shrink(cloud.colors);
  shrink(cloud.intensity);
  shrink(cloud.classification);
  shrink(cloud.returnNumber);
  shrink(cloud.pointSourceId);
}

} // namespace

PointCloud readOctreeCloud(NodeSource& source, const OctreeCloudOptions& options) {
  const OctreeMetadata& meta = source.metadata();
  std::vector<NodeInfo> nodes;
  forEachNode(source, [&](const NodeInfo& node) {
    nodes.push_back(node);
    return true;
  });
  std::vector<uint64_t> first(nodes.size() + 1, 0);
  for (size_t b = 0; b < nodes.size(); ++b)
    first[b + 1] = first[b] + nodes[b].pointCount;
  const uint64_t listed = first.back();

  RecordFields fields = meta.fields;
  if (!options.keepAttributes)
    fields.intensity = fields.classification = fields.returnNumber = fields.pointSourceId = false;
  PointCloud cloud;
  cloud.scale = meta.scale;
  cloud.offset = meta.offset;
  cloud.source = meta.source;
  cloud.positions.resize(3 * listed);
  if (fields.color) cloud.colors.resize(listed);
  if (fields.intensity) cloud.intensity.resize(listed);
  if (fields.classification) cloud.classification.resize(listed);
  if (fields.returnNumber) cloud.returnNumber.resize(listed);
  if (fields.pointSourceId) cloud.pointSourceId.resize(listed);

  std::optional<Progress> progress;
  if (options.progress) progress.emplace("reading " + meta.source, listed);
  int shift = meta.fields.colorMax > 255 ? 8 : 0;
  std::vector<uint64_t> actual(nodes.size(), 0);
  std::vector<uint16_t> colorMax(nodes.size(), 0);
  auto decode = [&](const RecordFields& into, bool measure) {
    parallelBlocks(nodes.size(), 1, [&](uint64_t b, uint64_t, uint64_t) {
      const std::vector<PointRecord> records = source.readNode(nodes[b]);
      if (records.size() > nodes[b].pointCount)
        throw InputError(meta.source + ": node " + nodes[b].key.potreeName() + " holds " +
                         std::to_string(records.size()) + " points, more than the " +
                         std::to_string(nodes[b].pointCount) + " its hierarchy lists");
      storeRecords(cloud, first[b], records.data(), records.size(), into, shift);
      if (!measure) return;
      actual[b] = records.size();
      if (into.color) colorMax[b] = largestChannel(records);
      if (progress) progress->advance(records.size());
    });
  };
  decode(fields, true);
  if (progress) progress->finish();
  // The guess was wrong (no or a wrong colorMax): decode again, colors only.
  const bool colors16 = !colorMax.empty() && *std::max_element(colorMax.begin(), colorMax.end()) > 255;
  if (fields.color && colors16 != (shift == 8)) {
    shift = colors16 ? 8 : 0;
    RecordFields colorOnly;
    colorOnly.color = true;
    decode(colorOnly, false);
  }
  uint64_t delivered = 0;
  for (uint64_t n : actual)
    delivered += n;
  if (delivered != listed) compact(cloud, first, actual);
  computeBounds(cloud);
  return cloud;
}

} // namespace pointrast::lod
