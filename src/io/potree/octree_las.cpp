// Octree -> LAS or LAZ export (writer.h): every node's records straight into LasRecordWriter, nodes
// decoded on all cores a batch at a time and written in forEachNode order.
#include <optional>

#include "base/parallel.h"
#include "base/progress.h"
#include "io/writer.h"

namespace pointrast::io {

namespace {

// Points decoded per batch (~100 MB of records): enough nodes to keep every core busy.
constexpr uint64_t kBatchPoints = uint64_t(4) << 20;

} // namespace

uint64_t writeLasFromOctree(const std::filesystem::path& path, lod::NodeSource& source, LasFlavor flavor,
                            bool progress) {
  const lod::OctreeMetadata& meta = source.metadata();
  std::vector<lod::NodeInfo> nodes;
  uint64_t listed = 0;
  lod::forEachNode(source, [&](const lod::NodeInfo& node) {
    nodes.push_back(node);
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
