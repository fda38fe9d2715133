#include "view/measure_tool.h"

#include <cassert>
#include <cmath>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace pointrast::view {

void MeasureTool::add(AnnotationKind kind, const glm::dvec3& point) {
  assert(kind == AnnotationKind::Distance || kind == AnnotationKind::Height || kind == AnnotationKind::Area);
  if (open_ && annotations_.items[*open_].kind != kind) finish();
  if (!open_) {
    Annotation a;
    a.kind = kind;
    annotations_.items.push_back(std::move(a));
    open_ = annotations_.items.size() - 1;
  }
  Annotation& a = annotations_.items[*open_];
  a.points.push_back(point);
  if (kind == AnnotationKind::Height && a.points.size() == 2) open_.reset();
  ++version_;
}

void MeasureTool::finish() {
  if (!open_) return;
  if (!annotationProblem(annotations_.items[*open_]).empty())
    annotations_.items.erase(annotations_.items.begin() + std::ptrdiff_t(*open_));
  open_.reset();
  ++version_;
}

bool MeasureTool::remove(size_t index) {
  if (index >= annotations_.items.size()) return false;
  annotations_.items.erase(annotations_.items.begin() + std::ptrdiff_t(index));
  if (open_ && *open_ == index)
    open_.reset();
  else if (open_ && *open_ > index)
    --*open_;
  ++version_;
  return true;
}

bool MeasureTool::move(size_t index, size_t vertex, const glm::dvec3& point) {
  if (index >= annotations_.items.size() || vertex >= annotations_.items[index].points.size()) return false;
  annotations_.items[index].points[vertex] = point;
  ++version_;
  return true;
}

std::optional<std::pair<size_t, size_t>> MeasureTool::vertexNear(const Camera& camera, double nearW,
                                                                 uint32_t width, uint32_t height,
                                                                 glm::dvec2 position, double radius) const {
  if (width == 0 || height == 0) return std::nullopt;
  // Relative to the eye, in double, as the overlay projects them (render/overlay.cpp).
  const glm::dmat4 vp = viewProjection(camera, camera.eye, double(width) / double(height));
  std::optional<std::pair<size_t, size_t>> best;
  double bestDistance = radius;
  for (size_t i = 0; i < annotations_.items.size(); ++i)
    for (size_t k = 0; k < annotations_.items[i].points.size(); ++k) {
      const glm::dvec4 c = vp * glm::dvec4(annotations_.items[i].points[k] - camera.eye, 1.0);
      if (!(c.w > nearW)) continue;
      // The marker's pixel centre (docs/design.md, "Camera and image").
      const glm::dvec2 at(std::floor((c.x / c.w + 1) / 2 * width) + 0.5,
                          std::floor((1 - c.y / c.w) / 2 * height) + 0.5);
      const double d = glm::length(at - position);
      if (d <= bestDistance) {
        bestDistance = d;
        best = {i, k};
      }
    }
  return best;
}

void MeasureTool::clear() {
  annotations_.items.clear();
  open_.reset();
  ++version_;
}

void MeasureTool::load(Annotations annotations) {
  annotations_ = std::move(annotations);
  open_.reset();
  ++version_;
}

Annotations MeasureTool::complete() const {
  Annotations out;
  out.unit = annotations_.unit;
  for (const Annotation& a : annotations_.items)
    if (annotationProblem(a).empty()) out.items.push_back(a);
  return out;
}

std::string MeasureTool::json() const {
  nlohmann::json list = nlohmann::json::array();
  for (size_t i = 0; i < annotations_.items.size(); ++i) {
    const Annotation& a = annotations_.items[i];
    nlohmann::json j;
    j["index"] = i;
    j["type"] = annotationKindName(a.kind);
    j["open"] = open_ && *open_ == i;
    nlohmann::json points = nlohmann::json::array();
    for (const glm::dvec3& p : a.points)
      points.push_back({p.x, p.y, p.z});
    j["points"] = points;
    if (!a.text.empty()) j["label"] = a.text;
    const std::string problem = annotationProblem(a);
    if (!problem.empty()) {
      j["problem"] = problem;
      list.push_back(j);
      continue;
    }
    const Measurement m = measure(a);
    // Each edge's 3D length, the closing edge of an area included.
    std::vector<double> segments;
    for (size_t k = 1; k < a.points.size(); ++k)
      segments.push_back(glm::length(a.points[k] - a.points[k - 1]));
    if (a.kind == AnnotationKind::Area) segments.push_back(glm::length(a.points.front() - a.points.back()));
    j["segments"] = segments;
    std::optional<double> value;
    if (a.kind == AnnotationKind::Distance) value = m.length;
    if (a.kind == AnnotationKind::Height) value = m.dz;
    if (a.kind == AnnotationKind::Area) value = m.area;
    if (a.kind == AnnotationKind::Angle) value = m.degrees;
    if (value) {
      j["value"] = *value;
      j["text"] = a.kind == AnnotationKind::Area    ? formatLength(*value, annotations_.unit) + "²"
                  : a.kind == AnnotationKind::Angle ? formatLength(*value, "") + "°"
                                                    : formatLength(*value, annotations_.unit);
    }
    list.push_back(j);
  }
  return list.dump();
}

} // namespace pointrast::view
