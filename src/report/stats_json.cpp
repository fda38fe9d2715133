#include "report/stats_json.h"

namespace pointrast::report {

nlohmann::json batchStatsJson(const BatchStats& b) {
  return {{"batches_processed", b.batchesProcessed},
          {"batches_rendered", b.batchesRendered},
          {"points_processed", b.pointsProcessed},
          {"points_rendered", b.pointsRendered},
          {"points_blended", b.pointsBlended},
          {"points_by_words", {b.pointsByWords[0], b.pointsByWords[1], b.pointsByWords[2]}},
          {"batches_dense", b.batchesDense},
          {"points_taken_back", b.pointsTakenBack},
          {"batches_redrawn", b.batchesRedrawn},
          {"batches_clipped", b.batchesClipped},
          {"bytes_read", b.bytesRead}};
}

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

} // namespace pointrast::report
