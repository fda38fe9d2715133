// Measurements of annotations against values computed here by hand, validity checks, and the clip volumes
// an annotations set hands to the point filter.
#include "cloud/annotations.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace pointrast {
namespace {

Annotation make(AnnotationKind kind, std::vector<glm::dvec3> points) {
  Annotation a;
  a.kind = kind;
  a.points = std::move(points);
  return a;
}

TEST(Annotations, DistanceSumsItsSegmentsIn3D) {
  // 3-4-12 and 2-3-6 right triangles: segments of 13 and 7.
  const Annotation a = make(AnnotationKind::Distance, {{1, 2, 3}, {4, 6, 15}, {6, 9, 21}});
  ASSERT_EQ(annotationProblem(a), "");
  const Measurement m = measure(a);
  ASSERT_EQ(m.segments.size(), 2u);
  EXPECT_DOUBLE_EQ(m.segments[0], 13.0);
  EXPECT_DOUBLE_EQ(m.segments[1], 7.0);
  EXPECT_DOUBLE_EQ(m.length, 20.0);
}

TEST(Annotations, HeightGivesDzHorizontalAndSlope) {
  const Annotation a = make(AnnotationKind::Height, {{10, 20, 105}, {13, 24, 93}});
  ASSERT_EQ(annotationProblem(a), "");
  const Measurement m = measure(a);
  EXPECT_DOUBLE_EQ(m.dz, -12.0);
  EXPECT_DOUBLE_EQ(m.horizontal, 5.0);
  EXPECT_DOUBLE_EQ(m.slope, 13.0);
}

TEST(Annotations, AreaIsHorizontalWithBothPerimeters) {
  // A 30 x 40 rectangle at UTM-sized coordinates, tilted so that one side rises 40 * 0.75 = 30 metres:
  // horizontal area 1200, horizontal perimeter 140; the tilted sides are 50 long in 3D.
  const double x0 = 500000.0, y0 = 5000000.0;
  const Annotation a = make(AnnotationKind::Area,
                            {{x0, y0, 100}, {x0 + 30, y0, 100}, {x0 + 30, y0 + 40, 130}, {x0, y0 + 40, 130}});
  ASSERT_EQ(annotationProblem(a), "");
  const Measurement m = measure(a);
  EXPECT_DOUBLE_EQ(m.area, 1200.0);
  EXPECT_DOUBLE_EQ(m.perimeter, 140.0);
  EXPECT_DOUBLE_EQ(m.perimeter3d, 160.0);
  // Clockwise order measures the same area.
  const Annotation reversed = make(AnnotationKind::Area, {a.points[3], a.points[2], a.points[1], a.points[0]});
  EXPECT_DOUBLE_EQ(measure(reversed).area, 1200.0);
}

TEST(Annotations, AngleAtTheMiddlePoint) {
  struct Case {
    glm::dvec3 a, b, c;
    double degrees;
  };
  const Case cases[] = {
      {{1, 0, 0}, {0, 0, 0}, {0, 1, 0}, 90.0},
      {{5, 5, 5}, {2, 2, 2}, {3, 3, 3}, 0.0},
      {{1, 0, 0}, {0, 0, 0}, {-2, 0, 0}, 180.0},
      {{1, 0, 0}, {0, 0, 0}, {1, std::sqrt(3.0), 0}, 60.0},
      {{10, 10, 10}, {10, 10, 0}, {10 + 1e-4, 10, 0 + 1e-4}, 45.0},
  };
  for (const Case& c : cases) {
    const Annotation a = make(AnnotationKind::Angle, {c.a, c.b, c.c});
    ASSERT_EQ(annotationProblem(a), "");
    EXPECT_NEAR(measure(a).degrees, c.degrees, 1e-9) << c.degrees;
  }
}

TEST(Annotations, ProblemsNameWhatIsWrong) {
  EXPECT_NE(annotationProblem(make(AnnotationKind::Distance, {{0, 0, 0}})).find("at least 2"), std::string::npos);
  EXPECT_NE(annotationProblem(make(AnnotationKind::Angle, {{0, 0, 0}, {1, 1, 1}})).find("exactly 3"),
            std::string::npos);
  EXPECT_NE(annotationProblem(make(AnnotationKind::Angle, {{0, 0, 0}, {0, 0, 0}, {1, 1, 1}})).find("differ"),
            std::string::npos);
  EXPECT_NE(annotationProblem(make(AnnotationKind::Label, {{0, 0, 0}})).find("text"), std::string::npos);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(annotationProblem(make(AnnotationKind::Point, {{0, nan, 0}})).find("finite"), std::string::npos);
  EXPECT_NE(annotationProblem(make(AnnotationKind::Point, {{0, 2e15, 0}})).find("finite"), std::string::npos);
  Annotation box;
  box.kind = AnnotationKind::ClipBox;
  box.box.halfExtent = {1, 1, 1};
  EXPECT_EQ(annotationProblem(box), "");
  box.box.axes[1] = {0.5, 1, 0};
  EXPECT_NE(annotationProblem(box).find("orthonormal"), std::string::npos);
  Annotation polygon;
  polygon.kind = AnnotationKind::ClipPolygon;
  polygon.polygon.vertices = {{0, 0}, {1, 0}};
  EXPECT_NE(annotationProblem(polygon).find("3 vertices"), std::string::npos);
  polygon.polygon.vertices.push_back({0, 1});
  EXPECT_EQ(annotationProblem(polygon), "");
  polygon.polygon.zMin = 5;
  polygon.polygon.zMax = 4;
  EXPECT_NE(annotationProblem(polygon).find("z range"), std::string::npos);
}

TEST(Annotations, ClipVolumesKeepTheirOrderAndDriveTheFilter) {
  Annotations set;
  Annotation box;
  box.kind = AnnotationKind::ClipBox;
  box.box.center = {10, 0, 0};
  box.box.halfExtent = {1, 1, 1};
  Annotation polygon;
  polygon.kind = AnnotationKind::ClipPolygon;
  polygon.polygon.vertices = {{0, 0}, {4, 0}, {0, 4}};
  polygon.polygon.zMax = 2;
  set.items = {make(AnnotationKind::Point, {{0, 0, 0}}), box, polygon};
  const PointFilter filter = clipVolumes(set);
  ASSERT_EQ(filter.orientedBoxes.size(), 1u);
  ASSERT_EQ(filter.polygons.size(), 1u);
  EXPECT_EQ(filter.orientedBoxes[0].center, glm::dvec3(10, 0, 0));
  EXPECT_TRUE(insideClip(filter, {10.5, 0.5, -0.5}));
  EXPECT_TRUE(insideClip(filter, {1, 1, -100}));
  EXPECT_FALSE(insideClip(filter, {1, 1, 3}));
  EXPECT_FALSE(insideClip(filter, {5, 5, 0}));
}

TEST(Annotations, LengthsPrintWithTheirUnit) {
  EXPECT_EQ(formatLength(12.345, "m"), "12.35 m");
  EXPECT_EQ(formatLength(-0.5, "ft"), "-0.50 ft");
  EXPECT_EQ(formatLength(123456.7, "m"), "123457 m");
  EXPECT_EQ(formatLength(3, ""), "3.00");
  for (const char* name : {"point", "distance", "height", "area", "angle", "label", "clip-box", "clip-polygon"})
    EXPECT_STREQ(annotationKindName(*parseAnnotationKind(name)), name);
  EXPECT_FALSE(parseAnnotationKind("volume"));
}

} // namespace
} // namespace pointrast
