// The JSON of a picked point, shared by render --pick and the viewers' pick tool.
#pragma once

#include <cstdint>
#include <optional>

#include <nlohmann/json.hpp>

#include "cloud/cloud.h"
#include "render/renderer.h"

namespace pointrast {

// {"pixel": [x, y], "point": ...}: "none" for the background, "unknown" where a point was drawn but none of
// the cloud matches its word, else every attribute the cloud holds (index, world coordinates, intensity,
// classification, return number, point source id, color).
nlohmann::json pickJson(const PointCloud& cloud, uint32_t x, uint32_t y, bool empty,
                        std::optional<uint64_t> index);

namespace lod {
class LodScene;
}
// The same for the point the renderer's last frame of `scene` drew at pixel (x, y) (Renderer::lodPointAt):
// its node is read from the octree's source, and "point" holds "node" (the node's Potree name, "r04"),
// "index" (the point's among the node's records) and every attribute the octree stores: the record's, as
// above, and where the points carry more (cloud/lod_tails.h) "gps_time", "number_of_returns", "scan_angle"
// (degrees), "user_data", "nir", the flags ("classification_flags", "scanner_channel",
// "scan_direction_flag", "edge_of_flight_line") and "extra_bytes" ({"name": value or [values]});
// "unavailable: ..." says why a frame cannot be picked from (Renderer::lodPointAt). Throws InputError for a
// damaged node.
nlohmann::json pickJson(Renderer& renderer, lod::LodScene& scene, uint32_t x, uint32_t y);

} // namespace pointrast
