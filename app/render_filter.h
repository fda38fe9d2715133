// The Filters group as the renderers take it, and render --pick. The renderer clips per frame
// (RenderSettings::filter); the attribute filters are applied once, when a cloud is loaded, and a
// highlight is folded into the uploaded colors (UploadOptions::filter).
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "cloud/point_filter.h"
#include "options.h"

namespace pointrast::app {

// pointFilter(a), checked against what the renderer's clip table holds (InputError otherwise).
PointFilter renderFilter(const FilterArgs& a);
// Keeps the points of a loaded cloud that pass the attribute filters (InputError naming the option when
// the cloud lacks the attribute); clip volumes are left to the renderer. Returns the points dropped.
uint64_t filterLoadedCloud(PointCloud& cloud, const PointFilter& filter);
// LOD sources take clip volumes only: InputError for attribute filters and --clip-mode highlight.
void checkOctreeFilter(const PointFilter& filter, const std::string& method);

// --pick X,Y: a pixel of a width x height image (row 0 at the top). InputError naming the option.
struct PixelPos {
  uint32_t x = 0, y = 0;
};
PixelPos parsePick(const std::string& text, uint32_t width, uint32_t height);
// The JSON of a picked point: "none" for the background, else every attribute the cloud holds (world
// coordinates, intensity, classification, return number, point source id, color).
nlohmann::json pickJson(const PointCloud& cloud, PixelPos pixel, bool empty, std::optional<uint64_t> index);

} // namespace pointrast::app
