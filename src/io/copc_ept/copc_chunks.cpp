// COPC chunks as nodes (copc_chunks.h). The node source serves each node's key, point count and chunk
// size; the LAZ chunk table each chunk's offset, size and point count. A (size, count) pair that appears
// exactly once on both sides names the same chunk; the rare chunk whose pair repeats is left out (its
// node unknown, a conversion decodes it and tests its points one by one).
#include "io/copc_ept/copc_chunks.h"

#include <algorithm>
#include <map>

#include "io/copc_ept/copc.h"
#include "io/io_util.h"
#include "io/las/laz_format.h"

namespace pointrast::io {

std::vector<CopcChunkCube> copcChunkCubes(const std::filesystem::path& path) {
  std::unique_ptr<lod::NodeSource> source = openCopc(path);
  const lod::OctreeMetadata& meta = source->metadata();
  const double grow = 2 * std::max({meta.scale.x, meta.scale.y, meta.scale.z});
  struct Side {
    int count = 0;
    Bounds cube;
    uint64_t offset = 0;
  };
  std::map<std::pair<uint64_t, uint64_t>, std::pair<Side, Side>> pairs; // (bytes, points): node, chunk
  lod::forEachNode(*source, [&](const lod::NodeInfo& node) {
    if (node.pointCount == 0) return true;
    Side& s = pairs[{source->nodeBytes(node), node.pointCount}].first;
    ++s.count;
    s.cube = meta.nodeCube(node.key);
    s.cube.min -= grow;
    s.cube.max += grow;
    return true;
  });
  detail::InputFile file(path);
  const laz::LazFile laz = laz::openLaz(file);
  for (const laz::Chunk& chunk : laz.chunks) {
    const auto it = pairs.find({chunk.bytes, chunk.pointCount});
    if (it == pairs.end()) continue;
    ++it->second.second.count;
    it->second.second.offset = chunk.offset;
  }
  std::vector<CopcChunkCube> out;
  for (const auto& [key, sides] : pairs)
    if (sides.first.count == 1 && sides.second.count == 1)
      out.push_back({sides.second.offset, sides.first.cube});
  return out;
}

} // namespace pointrast::io
