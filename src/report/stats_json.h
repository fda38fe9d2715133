// The counters of a frame as every JSON output writes them (`render --json`, the bench reports): a batched
// method's batches and points, and an LOD method's selection, drawing and streaming.
#pragma once

#include <nlohmann/json.hpp>

#include "render/lod/lod_stats.h"
#include "render/renderer.h"

namespace pointrast::report {

nlohmann::json batchStatsJson(const BatchStats& stats);
nlohmann::json lodStatsJson(const lod::LodStats& stats);

} // namespace pointrast::report
