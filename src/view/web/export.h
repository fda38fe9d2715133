// The browser viewer's exports: the points of the input inside the page's clip box (or outside it) and of
// the classes it keeps, as a LAS file the page downloads from /export.las, written by the convert path
// (io::convertLasFile with the filter, records byte for byte); and the profile along the page's line, as the
// PNG, LAS and CSV of /profile.png, /profile.las and /profile.csv, written by `pointrast profile`'s code
// (view::cutProfile). Each is written into a private temporary folder, streamed, and removed.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "cloud/point_filter.h"
#include "cloud/profile.h"

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

// A profile request's bounds: the vertices of its line and the sides of its picture (a picture of 4096 x
// 4096 is 64 MiB of RGBA on the server).
constexpr size_t kMaxProfileVertices = 256;
constexpr uint32_t kMaxProfilePictureSide = 4096;

enum class ProfileOutput { Png, Las, Csv };

struct ProfileQuery {
  ProfileLine line;
  uint32_t width = 0, height = 0; // the picture's size (Png only)
};

// The profile of a request's query string: line=x1,y1,x2,y2[,...] (2 to kMaxProfileVertices x/y vertices
// in the file's coordinates, not all at one place), width=W (the strip's width, positive), and for the
// picture size=WxH (200x120 to kMaxProfilePictureSide per side, as `profile --size`). InputError with one
// sentence for anything else: a missing, repeated or unknown parameter, a value that does not parse.
ProfileQuery parseProfileQuery(std::string_view query, ProfileOutput output);

// Cuts the profile of `input` (a point cloud file or an octree folder; empty: a generated scene, refused)
// with view::cutProfile into a fresh temporary folder as `output` (profile.png, profile.las or
// profile.csv), calls send(path, points) and removes the folder, also when send or the cut throws. Returns
// the profile's points.
uint64_t exportProfile(const std::string& input, const ProfileQuery& query, ProfileOutput output,
                       const std::function<void(const std::filesystem::path&, uint64_t)>& send);

} // namespace pointrast::view::web
