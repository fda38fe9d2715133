// A profile (cross section) cut from an input: the points within a strip along a polyline, drawn as a
// side view (render/profile_plot.h) and written as LAS/LAZ and CSV. `pointrast profile` and both viewers'
// profile panels call cutProfile, so that a viewer's picture and exports equal the command's.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cloud/point_filter.h"
#include "cloud/profile.h"

namespace pointrast::view {

struct ProfileRequest {
  std::string input; // a point cloud file or an octree (read node by node, culled by the strip)
  ProfileLine line;  // at least two vertices, width > 0, length > 0 (asserted)
  PointFilter filter;
  uint32_t imageWidth = 0, imageHeight = 0; // the side view's size; 0 x 0: no picture
  std::string las;                          // LAS or LAZ (by the extension) to write; empty: none
  std::string csv;                          // CSV to write; empty: none
  bool progress = false;
};

struct ProfileResult {
  uint64_t points = 0;          // the points within the strip that pass the filter
  std::vector<uint32_t> pixels; // imageWidth x imageHeight RGBA8, row 0 at the top; empty without a picture
};

// Reads the input once and writes the requested outputs, each under a temporary name then renamed. LAS,
// LAZ and COPC inputs keep their records byte for byte in the LAS output. Throws InputError for an input
// that cannot be read or lacks what the filter needs, and for an output that cannot be written.
ProfileResult cutProfile(const ProfileRequest& request);

// The least and greatest image sizes of a picture (the plot's axes and labels need room).
constexpr uint32_t kProfileMinWidth = 200, kProfileMinHeight = 120, kProfileMaxSide = 16384;

// Parses "x1,y1,x2,y2[,...]" into the line's vertices (its width untouched). Throws InputError naming
// `option` for anything else: too few or an odd count of numbers, a number that does not parse or is not
// finite, more than `maxVertices` vertices.
std::vector<glm::dvec2> parseProfileVertices(const std::string& text, const std::string& option,
                                             size_t maxVertices = 100000);

} // namespace pointrast::view
