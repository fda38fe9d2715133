#include "bench/lod_report.h"

namespace pointrast::bench {

nlohmann::json lodStatsJson(const lod::LodStats& s) {
  return {{"nodes_selected", s.nodesSelected},
          {"points_selected", s.pointsSelected},
          {"budget_reached", s.budgetReached},
          {"nodes_drawn", s.nodesDrawn},
          {"points_drawn", s.pointsDrawn},
          {"pages_drawn", s.pagesDrawn},
          {"passes", s.passes},
          {"converged", s.converged},
          {"stream_seconds", s.streamSeconds},
          {"nodes_loaded", s.nodesLoaded},
          {"bytes_streamed", s.bytesStreamed},
          {"bytes_uploaded", s.bytesUploaded},
          {"nodes_evicted", s.nodesEvicted},
          {"hierarchy_reads", s.hierarchyReads},
          {"resident_bytes", s.residentBytes},
          {"cache_bytes", s.cacheBytes}};
}

} // namespace pointrast::bench
