// The viewers' measuring tool over the annotations model (cloud/annotations.h): each picked point becomes a
// vertex of the measurement being drawn (distance, height or area); the list keeps what --annotations
// loaded too, and saves as an annotations file. Shared by the desktop panel and the browser page.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>

#include <glm/glm.hpp>

#include "cloud/annotations.h"
#include "render/camera.h"

namespace pointrast::view {

class MeasureTool {
public:
  // The kind the desktop's Ctrl+Shift+click measures (the panel's choice).
  AnnotationKind measureKind = AnnotationKind::Distance;

  // Adds a vertex to the open measurement of `kind` (Distance, Height or Area: an assert), opening a new
  // one when none is open or the open one is of another kind. A height closes itself at its second point.
  void add(AnnotationKind kind, const glm::dvec3& point);
  // The next point starts a new measurement; an open one that cannot be measured yet is dropped.
  void finish();
  // Removes annotation `index`; false when there is none.
  bool remove(size_t index);
  // Moves vertex `vertex` of annotation `index` to `point`; false when there is no such vertex.
  bool move(size_t index, size_t vertex, const glm::dvec3& point);
  // The vertex drawn nearest a position of a width x height image seen by `camera` (nearW: the near plane
  // the frame was drawn with), within `radius` pixels: (annotation, vertex). Vertices behind the near plane
  // are not seen; the latest annotation wins a tie.
  std::optional<std::pair<size_t, size_t>> vertexNear(const Camera& camera, double nearW, uint32_t width,
                                                      uint32_t height, glm::dvec2 position,
                                                      double radius) const;
  void clear();
  // Replaces the list (loaded from an annotations file); nothing is open.
  void load(Annotations annotations);
  // The annotations that can be measured and drawn (an open measurement of too few points left out).
  Annotations complete() const;
  const Annotations& all() const { return annotations_; }
  std::optional<size_t> open() const { return open_; }
  // Changes on every edit: front ends redraw overlays and resend the list when it moved.
  uint64_t version() const { return version_; }
  // The list as JSON text for a page or panel: [{"index", "type", "points", "open", "problem" or
  // "segments" (3D lengths), "value" (the total: length, height difference or area), "text"}].
  std::string json() const;

private:
  Annotations annotations_;
  std::optional<size_t> open_;
  uint64_t version_ = 0;
};

} // namespace pointrast::view
