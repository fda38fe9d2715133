// Measurements and annotations: points, polylines, polygons and clip volumes placed in a cloud, in the
// file's world coordinates (scale and offset applied). One model for every consumer: `render --annotations`
// draws them over the image (render/overlay.h), the viewers edit them, and the clip volumes among them feed
// the point filter (cloud/point_filter.h). io/annotations_file.h reads and writes them as JSON.
//
// What each kind measures (all distances in the file's units, 3D unless said):
//   point     one point
//   distance  a polyline of >= 2 points: each segment's length and their sum
//   height    two points: the height difference dz = z1 - z0, the horizontal distance (x/y only) and the
//             slope distance (3D)
//   area      a polygon of >= 3 points, closed (the last point joins the first): the area of its projection
//             on the x/y plane (shoelace formula, absolute), the horizontal perimeter and the 3D perimeter
//   angle     three points: the angle at the middle one, in degrees (0..180)
//   label     one point and a text
//   clip-box, clip-polygon: the clip volumes of point_filter.h
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cloud/point_filter.h"

namespace pointrast {

enum class AnnotationKind : uint8_t { Point, Distance, Height, Area, Angle, Label, ClipBox, ClipPolygon };

// "point", "distance", "height", "area", "angle", "label", "clip-box", "clip-polygon".
const char* annotationKindName(AnnotationKind kind);
std::optional<AnnotationKind> parseAnnotationKind(const std::string& name);

struct Annotation {
  AnnotationKind kind = AnnotationKind::Point;
  std::string text;                     // shown beside the annotation; required for a label
  std::optional<std::array<uint8_t, 3>> color; // RGB; unset: the kind's own color
  std::vector<glm::dvec3> points;       // the measured points (none for the clip volumes)
  OrientedClipBox box;                  // clip-box only
  ClipPolygon polygon;                  // clip-polygon only
};

// The largest coordinate magnitude an annotation may hold: the renderer's own limit (render/camera.h).
inline constexpr double kMaxAnnotationCoordinate = 1e15;

struct Annotations {
  std::string unit; // appended to measured values ("m"); empty: none
  std::vector<Annotation> items;
};

// The values a kind measures; the fields of other kinds stay 0.
struct Measurement {
  std::vector<double> segments; // distance: each segment's 3D length
  double length = 0;            // distance: the sum of the segments
  double dz = 0, horizontal = 0, slope = 0; // height
  double area = 0, perimeter = 0, perimeter3d = 0; // area (perimeter is horizontal)
  double degrees = 0;                              // angle
};

// Why an annotation cannot be measured or drawn, in a few words ("needs at least 2 points", "the axes
// are not orthonormal"); empty when it is valid. Checks the point count for its kind, finite coordinates
// within kMaxAnnotationCoordinate, an angle's legs of non-zero length, a box's axes (orthonormal within 1e-6) and
// half extents (finite, >= 0), a polygon's vertices (>= 3, finite) and z range (zMin <= zMax, not NaN).
std::string annotationProblem(const Annotation& annotation);

// The measurement of a valid annotation (annotationProblem is empty).
Measurement measure(const Annotation& annotation);

// The clip volumes among the annotations, in their order, as a filter's boxes and polygons (clip mode and
// attribute filters left at their defaults).
PointFilter clipVolumes(const Annotations& annotations);

// "12.35 m": a measured value with two decimals (none from 100000 up) and the unit.
std::string formatLength(double value, const std::string& unit);

} // namespace pointrast
