// Profiles (cross sections): the points within a strip along a polyline in x/y, placed by their distance
// along the line. Pure geometry, no files.
//
// A point q belongs to the strip of a polyline v0..vn (n >= 1 segments) and width W when its horizontal
// distance to the polyline is at most W / 2. That distance is the least, over the segments, of the x/y
// distance from q to the nearest point of the closed segment: perpendicular to the segment where the foot
// of the perpendicular falls within it, else to the nearer end point. The strip is therefore W wide along
// every segment, with half-disc caps at the line's two ends and round joints. The point's distance along
// the line is the station of that nearest point (the length of the polyline up to it), on the first
// segment that attains the least distance; its offset is the signed distance, positive to the left of
// the line's direction.
#pragma once

#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "cloud/cloud.h"

namespace pointrast {

struct ProfileLine {
  std::vector<glm::dvec2> vertices; // at least 2
  double width = 0;                 // > 0
};

struct ProfilePlace {
  double distance = 0; // along the line, 0 at the first vertex
  double offset = 0;   // signed, positive to the left of the line's direction
};

// The place of a point within the strip, or nothing when it lies outside.
std::optional<ProfilePlace> profilePlace(const ProfileLine& line, const glm::dvec2& q);
// The polyline's length (the largest distance a point can have).
double profileLength(const ProfileLine& line);
// The x/y bounds of the strip (z unbounded), for culling whole nodes.
Bounds profileBounds(const ProfileLine& line);

} // namespace pointrast
