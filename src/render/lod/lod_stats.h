// What the LOD methods report (FrameStats::lod): the CPU's node selection, the nodes a frame drew, and the
// streaming of nodes from their source into the GPU node cache (the 2022 paper's Table 2 for octrees, plus
// what out-of-core rendering adds).
#pragma once

#include <cstdint>

namespace pointrast::lod {

struct LodStats {
  uint64_t nodesSelected = 0, pointsSelected = 0; // the CPU's selection for the camera
  bool budgetReached = false;                     // a budget (points, or the cache's pages) cut it short
  uint64_t nodesDrawn = 0, pointsDrawn = 0;       // drawn: the resident part of the selection (all of it
  uint64_t pagesDrawn = 0;                        // once converged), over every pass
  uint32_t passes = 0;      // passes of a frame (more than 1 when the selection exceeds the cache)
  bool converged = false;   // the frame drew the whole selection
  bool changed = false;     // frame by frame: the frame differs from the previous one (draw again)
  double streamSeconds = 0; // offline: wall time until the selection (every pass of it) was resident
  // Totals since the scene was made:
  uint64_t nodesLoaded = 0;    // nodes read and uploaded
  uint64_t bytesStreamed = 0;  // bytes of the source's files those nodes occupy (NodeSource::nodeBytes)
  uint64_t bytesUploaded = 0;  // bytes copied into the node cache
  uint64_t nodesEvicted = 0;   // nodes dropped from the cache to make room
  uint64_t hierarchyReads = 0; // children lists read
  uint64_t residentBytes = 0;  // node cache pages in use
  uint64_t cacheBytes = 0;     // the cache's budget (whole pages)
};

} // namespace pointrast::lod
