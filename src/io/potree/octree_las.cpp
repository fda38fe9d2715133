// Octree -> LAS or LAZ export (writer.h): every node's records straight into LasRecordWriter, nodes
// decoded on all cores a batch at a time and written in forEachNode order.
#include <algorithm>
#include <optional>

#include "base/parallel.h"
#include "base/progress.h"
#include "io/writer.h"

namespace pointrast::io {

namespace {

// Points decoded per batch (~100 MB of records): enough nodes to keep every core busy.
constexpr uint64_t kBatchPoints = uint64_t(4) << 20;

// The point as a filter sees it: a record holds no number of returns and no GPS time (the caller has
// refused filters on them).
FilterPoint filterPoint(const PointRecord& r, const lod::OctreeMetadata& meta) {
  FilterPoint p;
  p.position = glm::dvec3(r.x, r.y, r.z) * meta.scale + meta.offset;
  p.classification = r.classification;
  p.returnNumber = r.returnNumber;
  p.intensity = r.intensity;
  p.pointSourceId = r.pointSourceId;
  return p;
}

} // namespace

uint64_t writeLasFromOctree(const std::filesystem::path& path, lod::NodeSource& source, LasFlavor flavor,
                            bool progress, const PointFilter* filter, ClipNodeStats* nodeStats) {
  const lod::OctreeMetadata& meta = source.metadata();
  if (filter && !filter->active()) filter = nullptr;
  PointFilter attributesOnly; // for nodes the clip keeps as a whole
  if (filter) {
    attributesOnly = *filter;
    attributesOnly.boxes.clear();
    attributesOnly.orientedBoxes.clear();
    attributesOnly.polygons.clear();
  }
  // A node's points lie in its cube, up to rounding onto its faces: two quantization steps of margin.
  const double grow = 2 * std::max({meta.scale.x, meta.scale.y, meta.scale.z});
  std::vector<lod::NodeInfo> nodes;
  std::vector<BoxVerdict> verdicts;
  uint64_t listed = 0;
  lod::forEachNode(source, [&](const lod::NodeInfo& node) {
    BoxVerdict v = BoxVerdict::Some;
    if (filter && filter->hasClip()) {
      Bounds cube = meta.nodeCube(node.key);
      cube.min -= grow;
      cube.max += grow;
      v = clipVerdict(*filter, cube);
      if (nodeStats) {
        ++nodeStats->nodes;
        nodeStats->skipped += v == BoxVerdict::None;
      }
      if (v == BoxVerdict::None) return true;
    }
    nodes.push_back(node);
    verdicts.push_back(v);
    listed += node.pointCount;
    return true;
  });
  LasRecordWriter writer(path, meta.scale, meta.offset, meta.fields, flavor);
  std::optional<Progress> line;
  if (progress) line.emplace("exporting " + meta.source, listed);
  for (size_t begin = 0; begin < nodes.size();) {
    size_t end = begin;
    uint64_t points = 0;
    while (end < nodes.size() && (end == begin || points + nodes[end].pointCount <= kBatchPoints))
      points += nodes[end++].pointCount;
    std::vector<std::vector<PointRecord>> batch(end - begin);
    parallelBlocks(end - begin, 1, [&](uint64_t k, uint64_t, uint64_t) {
      batch[k] = source.readNode(nodes[begin + k]);
      if (line) line->advance(batch[k].size());
      if (filter) {
        const PointFilter& test = verdicts[begin + k] == BoxVerdict::All ? attributesOnly : *filter;
        std::erase_if(batch[k], [&](const PointRecord& r) { return !passes(test, filterPoint(r, meta)); });
      }
    });
    for (const std::vector<PointRecord>& records : batch)
      writer.write(records.data(), records.size());
    begin = end;
  }
  if (line) line->finish();
  const uint64_t written = writer.pointsWritten();
  writer.commit();
  return written;
}

} // namespace pointrast::io
