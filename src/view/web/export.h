// The browser viewer's export: the points of the input inside the page's clip box (or outside it) and of
// the classes it keeps, as a LAS file the page downloads from /export.las. Written by the convert path
// (io::convertLasFile with the filter, records byte for byte) into a private temporary folder, streamed,
// and removed.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "cloud/point_filter.h"

namespace pointrast::view::web {

// What the server can export: the input file (LAS, LAZ or COPC), or why not, in one sentence.
struct ExportSource {
  std::optional<std::filesystem::path> file;
  std::string whyNot;
};
ExportSource exportSource(const std::string& input);

// The filter of an export request's query string: box=x0,y0,z0,x1,y1,z1 (min then max corner),
// mode=inside|outside (with a box; default inside), classes=2,6 (ASPRS classes 0-255 to keep). InputError
// with one sentence for anything else.
PointFilter parseExportQuery(std::string_view query);

// Writes the points of `source` that pass `filter` as LAS into a fresh temporary folder, calls
// send(path, points) and removes the folder, also when send or the writer throws. Returns the points.
uint64_t exportLas(const std::filesystem::path& source, const PointFilter& filter,
                   const std::function<void(const std::filesystem::path&, uint64_t)>& send);

} // namespace pointrast::view::web
