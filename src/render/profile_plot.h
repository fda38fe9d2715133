// A profile's side view drawn on the CPU: an orthographic view of the strip's points (x: distance along
// the line, y: elevation), z-buffered by their offset from the line, with a frame, ticks and labels.
#pragma once

#include <cstdint>
#include <vector>

namespace pointrast {

struct ProfileSample {
  double distance = 0, elevation = 0;
  double depth = 0;   // smaller is nearer the viewer and wins its pixels
  uint32_t color = 0; // packRgba
};

struct ProfilePlot {
  uint32_t width = 1200, height = 500; // the whole image, axes and labels included
  double length = 0;                   // distance axis: 0..length
  int pointSize = 2;                   // pixels per point, square
};

// RGBA8 pixels, row 0 at the top. The elevation axis spans the samples' range with a small margin; both
// axes are labeled in the input's units. Preconditions: width >= 200, height >= 120, length > 0.
std::vector<uint32_t> plotProfile(const std::vector<ProfileSample>& samples, const ProfilePlot& plot);

} // namespace pointrast
