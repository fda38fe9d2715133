// Profile strips (profile.h).
#include "cloud/profile.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pointrast {

std::optional<ProfilePlace> profilePlace(const ProfileLine& line, const glm::dvec2& q) {
  const double half = 0.5 * line.width;
  double best = std::numeric_limits<double>::infinity(), station = 0;
  ProfilePlace place;
  for (size_t i = 0; i + 1 < line.vertices.size(); ++i) {
    const glm::dvec2 a = line.vertices[i], b = line.vertices[i + 1], ab = b - a;
    const double length2 = glm::dot(ab, ab), length = std::sqrt(length2);
    const double t = length2 > 0 ? std::clamp(glm::dot(q - a, ab) / length2, 0.0, 1.0) : 0.0;
    const glm::dvec2 foot = a + t * ab, d = q - foot;
    const double distance = std::sqrt(glm::dot(d, d));
    if (distance < best) {
      best = distance;
      place.distance = station + t * length;
      // Left of the direction: the cross product ab x (q - a) is positive; a zero-length segment has no
      // direction, its offset is the distance.
      const double side = length2 > 0 ? ab.x * (q.y - a.y) - ab.y * (q.x - a.x) : 1.0;
      place.offset = side >= 0 ? distance : -distance;
    }
    station += length;
  }
  if (!(best <= half)) return std::nullopt;
  return place;
}

double profileLength(const ProfileLine& line) {
  double length = 0;
  for (size_t i = 0; i + 1 < line.vertices.size(); ++i)
    length += glm::length(line.vertices[i + 1] - line.vertices[i]);
  return length;
}

Bounds profileBounds(const ProfileLine& line) {
  Bounds b;
  const double half = 0.5 * line.width;
  for (const glm::dvec2& v : line.vertices) {
    b.expand(glm::dvec3(v.x - half, v.y - half, -std::numeric_limits<double>::infinity()));
    b.expand(glm::dvec3(v.x + half, v.y + half, std::numeric_limits<double>::infinity()));
  }
  return b;
}

} // namespace pointrast
