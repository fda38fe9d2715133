#include "render/clip_volumes.h"

#include <bit>
#include <string>

#include "base/error.h"

namespace pointrast {

namespace {

void requireAtMost(size_t count, uint32_t limit, const char* what) {
  if (count > limit)
    throw InputError(std::to_string(count) + " " + what + " given; the renderer draws at most " +
                     std::to_string(limit));
}

glm::vec4 relative(const glm::dvec3& p, const glm::dvec3& origin) {
  return glm::vec4(glm::vec3(p - origin), 0.0f);
}

} // namespace

void checkGpuClip(const PointFilter& filter) {
  requireAtMost(filter.boxes.size(), shared::kMaxClipBoxes, "clip boxes");
  requireAtMost(filter.orientedBoxes.size(), shared::kMaxClipOrientedBoxes, "oriented clip boxes");
  requireAtMost(filter.polygons.size(), shared::kMaxClipPolygons, "clip polygons");
  size_t vertices = 0;
  for (const ClipPolygon& polygon : filter.polygons) {
    if (polygon.vertices.size() < 3)
      throw InputError("a clip polygon needs at least 3 vertices, one has " +
                       std::to_string(polygon.vertices.size()));
    vertices += polygon.vertices.size();
  }
  requireAtMost(vertices, shared::kMaxClipVertices, "clip polygon vertices in all");
}

shared::ClipVolumes gpuClipVolumes(const PointFilter& filter, const glm::dvec3& origin) {
  checkGpuClip(filter);
  shared::ClipVolumes c{};
  if (!filter.hasClip() || filter.clipMode == ClipMode::Highlight) {
    c.mode = shared::kClipNone;
    return c;
  }
  c.mode = filter.clipMode == ClipMode::Inside ? shared::kClipInside : shared::kClipOutside;
  c.boxes = uint32_t(filter.boxes.size());
  for (size_t i = 0; i < filter.boxes.size(); ++i) {
    // Rounding is monotonic: a point inside the exact box stays inside the rounded one.
    c.box[2 * i] = relative(filter.boxes[i].min, origin);
    c.box[2 * i + 1] = relative(filter.boxes[i].max, origin);
  }
  c.orientedBoxes = uint32_t(filter.orientedBoxes.size());
  for (size_t i = 0; i < filter.orientedBoxes.size(); ++i) {
    const OrientedClipBox& box = filter.orientedBoxes[i];
    c.oriented[4 * i] = relative(box.center, origin);
    for (int k = 0; k < 3; ++k)
      c.oriented[4 * i + 1 + k] = glm::vec4(glm::vec3(box.axes[k]), float(box.halfExtent[k]));
  }
  c.polygons = uint32_t(filter.polygons.size());
  uint32_t vertex = 0;
  auto vertexSlot = [&](uint32_t j) -> float* { return &c.vertices[j / 2][int(j % 2) * 2]; };
  for (size_t i = 0; i < filter.polygons.size(); ++i) {
    const ClipPolygon& polygon = filter.polygons[i];
    const uint32_t count = uint32_t(polygon.vertices.size());
    // Infinite z bounds stay infinite: relative to any origin they bound nothing.
    const float zMin = float(polygon.zMin - origin.z), zMax = float(polygon.zMax - origin.z);
    c.polygon[i] = glm::vec4(std::bit_cast<float>(vertex), std::bit_cast<float>(count), zMin, zMax);
    for (const glm::dvec2& v : polygon.vertices) {
      float* slot = vertexSlot(vertex++);
      slot[0] = float(v.x - origin.x);
      slot[1] = float(v.y - origin.y);
    }
  }
  return c;
}

} // namespace pointrast
