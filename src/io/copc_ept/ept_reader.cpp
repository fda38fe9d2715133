// An EPT dataset as one cloud (readCloud) and as `info` describes it, both through its NodeSource.
#include <optional>

#include "base/parallel.h"
#include "base/progress.h"
#include "io/copc_ept/ept.h"
#include "io/io_util.h"

namespace pointrast::io {

using namespace detail;
using lod::NodeInfo;

namespace {

std::vector<NodeInfo> allNodes(lod::NodeSource& source) {
  std::vector<NodeInfo> nodes;
  lod::forEachNode(source, [&](const NodeInfo& n) {
    nodes.push_back(n);
    return true;
  });
  return nodes;
}

uint16_t colorMax(const std::vector<PointRecord>& records) {
  uint16_t hi = 0;
  for (const PointRecord& r : records)
    hi = std::max({hi, r.rgb[0], r.rgb[1], r.rgb[2]});
  return hi;
}

} // namespace

PointCloud readEpt(const std::filesystem::path& path, const ReadOptions& options) {
  const std::unique_ptr<lod::NodeSource> source = openEpt(path);
  const lod::OctreeMetadata& meta = source->metadata();
  PointCloud cloud;
  cloud.source = meta.source;
  cloud.scale = meta.scale;
  cloud.offset = meta.offset;
  RecordFields fields = meta.fields;
  if (!options.keepAttributes) fields.intensity = fields.classification = fields.returnNumber = false;
  const std::vector<NodeInfo> nodes = allNodes(*source);

  std::optional<Progress> progress;
  if (options.progress) progress.emplace("reading " + meta.source, meta.pointCount);
  // Nodes decode in parallel windows and append in depth-first order. Colors as in the LAZ reader:
  // each node by its own depth, the 8-bit ones blacked out if any node turns out 16-bit.
  const size_t window = 2 * size_t(hardwareThreads());
  std::vector<std::vector<PointRecord>> records(window);
  bool colors16 = false;
  std::vector<std::pair<uint64_t, uint64_t>> converted8;
  for (size_t first = 0; first < nodes.size(); first += window) {
    const size_t n = std::min(window, nodes.size() - first);
    parallelBlocks(n, 1,
                   [&](uint64_t i, uint64_t, uint64_t) { records[i] = source->readNode(nodes[first + i]); });
    for (size_t i = 0; i < n; ++i) {
      const int shift = fields.color && colorMax(records[i]) > 255 ? 8 : 0;
      if (shift)
        colors16 = true;
      else
        converted8.emplace_back(cloud.size(), records[i].size());
      appendRecords(cloud, records[i].data(), records[i].size(), fields, shift);
      if (progress) progress->advance(records[i].size());
    }
  }
  if (progress) progress->finish();
  if (colors16)
    for (const auto& [begin, count] : converted8)
      std::fill_n(cloud.colors.begin() + static_cast<ptrdiff_t>(begin), count, packRgba(0, 0, 0));
  computeBounds(cloud);
  for (int a = 0; a < 3; ++a)
    if (cloud.size() && (!std::isfinite(cloud.bounds.min[a]) || !std::isfinite(cloud.bounds.max[a])))
      fail(path, "coordinates overflow after applying the schema's scale and offset");
  return cloud;
}

namespace detail {

FileInfo probeEpt(const std::filesystem::path& path) {
  const std::unique_ptr<lod::NodeSource> source = openEpt(path);
  const lod::OctreeMetadata& meta = source->metadata();
  FileInfo info;
  info.formatDetail = meta.format;
  info.pointCount = meta.pointCount;
  info.bounds = meta.bounds;
  info.boundsFromHeader = true;
  info.scale = meta.scale;
  info.offset = meta.offset;
  info.hasColor = meta.fields.color;
  const NodeInfo root = source->root();
  const std::vector<NodeInfo> level1 = source->children(root);
  if (info.hasColor) {
    // Datasets hold billions of points: the bit depth is judged from the root and its children.
    uint16_t lo = UINT16_MAX, hi = 0;
    std::vector<NodeInfo> sample = level1;
    sample.push_back(root);
    for (const NodeInfo& n : sample)
      for (const PointRecord& r : source->readNode(n))
        for (uint16_t v : r.rgb) {
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
    info.colorBits = hi > 255 ? 16 : 8;
    if (hi >= lo) info.extra.emplace_back("color values", strFormat("%u .. %u (root and level 1)", lo, hi));
  }
  const Bounds& c = meta.cube;
  info.extra.emplace_back("cube", strFormat("%.6f, %.6f, %.6f .. %.6f, %.6f, %.6f", c.min.x, c.min.y, c.min.z,
                                            c.max.x, c.max.y, c.max.z));
  info.extra.emplace_back("spacing", strFormat("%g at the root", meta.spacing));
  uint64_t level1Points = 0;
  for (const NodeInfo& n : level1)
    level1Points += n.pointCount;
  info.extra.emplace_back("hierarchy",
                          strFormat("root %llu points, %zu children with %llu",
                                    static_cast<unsigned long long>(root.pointCount), level1.size(),
                                    static_cast<unsigned long long>(level1Points)));
  return info;
}

} // namespace detail

} // namespace pointrast::io
