// The JSON of a picked point, shared by render --pick and the viewers' pick tool.
#pragma once

#include <cstdint>
#include <optional>

#include <nlohmann/json.hpp>

#include "cloud/cloud.h"

namespace pointrast {

// {"pixel": [x, y], "point": ...}: "none" for the background, "unknown" where a point was drawn but none of
// the cloud matches its word, else every attribute the cloud holds (index, world coordinates, intensity,
// classification, return number, point source id, color).
nlohmann::json pickJson(const PointCloud& cloud, uint32_t x, uint32_t y, bool empty,
                        std::optional<uint64_t> index);

} // namespace pointrast
