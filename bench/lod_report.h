// JSON of the LOD methods' statistics (render --json and the bench): the CPU's node selection, the nodes
// drawn, and the streaming of nodes from their source into the GPU node cache.
#pragma once

#include <nlohmann/json.hpp>

#include "render/lod/lod_stats.h"

namespace pointrast::bench {

nlohmann::json lodStatsJson(const lod::LodStats& stats);

} // namespace pointrast::bench
