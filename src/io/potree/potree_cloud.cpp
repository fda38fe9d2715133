// Potree 2.0 octrees as a whole cloud (readCloud) and as a file description (probeFile, `info`).
#include "cloud/octree_cloud.h"
#include "io/formats.h"
#include "io/io_util.h"
#include "io/potree/potree.h"

namespace pointrast::io {

using namespace detail;

PointCloud readPotree(const std::filesystem::path& path, const ReadOptions& options) {
  std::unique_ptr<lod::NodeSource> source = openPotree(path);
  lod::OctreeCloudOptions o;
  o.progress = options.progress;
  o.keepAttributes = options.keepAttributes;
  return lod::readOctreeCloud(*source, o);
}

namespace detail {

namespace {

std::string describeAttributes(const PotreeFolderInfo& folder) {
  std::string out;
  for (const PotreeAttributeInfo& a : folder.attributes) {
    if (!out.empty()) out += ", ";
    out += a.name + " (" + a.type + (a.numElements > 1 ? " x" + std::to_string(a.numElements) : "") + ")";
  }
  return out;
}

std::string box(const Bounds& b) {
  return strFormat("%.6f, %.6f, %.6f .. %.6f, %.6f, %.6f", b.min.x, b.min.y, b.min.z, b.max.x, b.max.y,
                   b.max.z);
}

} // namespace

FileInfo probePotreeFolder(const std::filesystem::path& path) {
  const PotreeFolderInfo folder = probePotree(path);
  std::unique_ptr<lod::NodeSource> source = openPotree(path);
  const lod::OctreeMetadata& meta = source->metadata();
  uint64_t nodes = 0, points = 0;
  int depth = 0;
  lod::forEachNode(*source, [&](const lod::NodeInfo& node) {
    ++nodes;
    points += node.pointCount;
    depth = std::max(depth, int(node.key.level));
    return true;
  });

  FileInfo info;
  info.formatDetail =
      "Potree 2.0 octree, " + folder.encoding + " encoding, written by " +
      (folder.fromPointrast ? std::string("pointrast") : "PotreeConverter (no \"generator\" field)");
  info.pointCount = meta.pointCount;
  info.bounds = meta.bounds;
  info.boundsFromHeader = true;
  info.scale = meta.scale;
  info.offset = meta.offset;
  info.hasColor = meta.fields.color;
  info.colorBits = meta.fields.colorMax > 255 ? 16 : 8;
  auto& extra = info.extra;
  if (!folder.name.empty()) extra.emplace_back("name", folder.name);
  if (!folder.description.empty()) extra.emplace_back("description", folder.description);
  if (!folder.projection.empty()) extra.emplace_back("projection", folder.projection);
  extra.emplace_back("nodes", std::to_string(nodes));
  extra.emplace_back("depth", strFormat("%d levels below the root", depth));
  if (points != meta.pointCount)
    extra.emplace_back("points in nodes",
                       strFormat("%llu (metadata.json states %llu)", static_cast<unsigned long long>(points),
                                 static_cast<unsigned long long>(meta.pointCount)));
  extra.emplace_back("spacing", strFormat("%g at the root, %g at level %d", meta.spacing,
                                          meta.nodeSpacing(lod::NodeKey{depth, 0, 0, 0}), depth));
  extra.emplace_back("cube", box(meta.cube));
  extra.emplace_back("attributes", describeAttributes(folder));
  extra.emplace_back("encoding", folder.encoding);
  extra.emplace_back("hierarchy", strFormat("chunks of %d levels, first chunk %llu bytes", folder.stepSize,
                                            static_cast<unsigned long long>(folder.firstChunkSize)));
  if (folder.fromPointrast) {
    extra.emplace_back("coordinates", "exact (rounded by pointrast)");
  } else {
    extra.emplace_back("writer", "PotreeConverter, or another writer without a \"generator\" field");
    extra.emplace_back(
        "coordinates",
        std::string("may sit one quantum low (PotreeConverter truncates when it quantizes)") +
            (folder.encoding == "BROTLI" ? "; its BROTLI shift of one quantum is undone" : ""));
  }
  return info;
}

} // namespace detail

} // namespace pointrast::io
