#include "cloud/point_filter.h"

#include <random>

#include <gtest/gtest.h>

#include "base/error.h"

namespace pointrast {
namespace {

FilterPoint at(double x, double y, double z) {
  FilterPoint p;
  p.position = {x, y, z};
  return p;
}

Bounds bounds(glm::dvec3 lo, glm::dvec3 hi) {
  Bounds b;
  b.min = lo;
  b.max = hi;
  return b;
}

TEST(PointFilter, EmptyFilterKeepsEverything) {
  PointFilter f;
  EXPECT_FALSE(f.active());
  EXPECT_TRUE(passes(f, at(1e9, -5, 3)));
  EXPECT_FALSE(insideClip(f, {0, 0, 0}));
  EXPECT_EQ(clipVerdict(f, bounds({0, 0, 0}, {1, 1, 1})), BoxVerdict::All);
}

TEST(PointFilter, BoxBoundariesAreInside) {
  PointFilter f;
  f.boxes.push_back({{0, 0, 0}, {10, 20, 30}});
  EXPECT_TRUE(passes(f, at(0, 0, 0)));
  EXPECT_TRUE(passes(f, at(10, 20, 30)));
  EXPECT_TRUE(passes(f, at(5, 5, 5)));
  EXPECT_FALSE(passes(f, at(10.001, 5, 5)));
  EXPECT_FALSE(passes(f, at(5, 5, -0.001)));
  f.clipMode = ClipMode::Outside;
  EXPECT_FALSE(passes(f, at(5, 5, 5)));
  EXPECT_TRUE(passes(f, at(11, 5, 5)));
  f.clipMode = ClipMode::Highlight;
  EXPECT_TRUE(passes(f, at(11, 5, 5)));
  EXPECT_TRUE(insideClip(f, {5, 5, 5}));
  EXPECT_FALSE(insideClip(f, {11, 5, 5}));
}

TEST(PointFilter, UnionOfVolumes) {
  PointFilter f;
  f.boxes.push_back({{0, 0, 0}, {1, 1, 1}});
  f.boxes.push_back({{5, 5, 5}, {6, 6, 6}});
  EXPECT_TRUE(passes(f, at(0.5, 0.5, 0.5)));
  EXPECT_TRUE(passes(f, at(5.5, 5.5, 5.5)));
  EXPECT_FALSE(passes(f, at(3, 3, 3)));
}

TEST(PointFilter, OrientedBox) {
  PointFilter f;
  OrientedClipBox b;
  b.center = {10, 10, 0};
  const double s = std::sqrt(0.5);
  b.axes = {glm::dvec3(s, s, 0), glm::dvec3(-s, s, 0), glm::dvec3(0, 0, 1)};
  b.halfExtent = {4, 1, 2};
  f.orientedBoxes.push_back(b);
  EXPECT_TRUE(passes(f, at(12, 12, 0)));    // 2.83 along the long axis
  EXPECT_FALSE(passes(f, at(12, 8, 0)));    // 2.83 along the short axis
  EXPECT_FALSE(passes(f, at(10, 10, 2.5))); // above
  EXPECT_TRUE(passes(f, at(10, 10, -2)));   // on the bottom face
}

TEST(PointFilter, PolygonEvenOddAndZRange) {
  PointFilter f;
  ClipPolygon poly; // a "C" shape: the notch at x 1..3, y 1..2 is outside
  poly.vertices = {{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 2}, {3, 2}, {3, 3}, {0, 3}};
  f.polygons.push_back(poly);
  EXPECT_TRUE(passes(f, at(0.5, 1.5, 100)));
  EXPECT_TRUE(passes(f, at(2, 0.5, -100)));
  EXPECT_FALSE(passes(f, at(2, 1.5, 0)));
  EXPECT_FALSE(passes(f, at(4, 1.5, 0)));
  // A self-overlapping outline: even-odd leaves the doubly covered part outside.
  PointFilter twice;
  ClipPolygon star;
  star.vertices = {{0, 0}, {4, 0}, {4, 4}, {1, 4}, {1, 1}, {3, 1}, {3, 3}, {0, 3}};
  twice.polygons.push_back(star);
  EXPECT_TRUE(passes(twice, at(0.5, 0.5, 0)));
  EXPECT_FALSE(passes(twice, at(2, 2, 0))); // inside the loop the outline makes around itself
  f.polygons[0].zMin = 0;
  f.polygons[0].zMax = 10;
  EXPECT_TRUE(passes(f, at(0.5, 1.5, 10)));
  EXPECT_FALSE(passes(f, at(0.5, 1.5, 10.5)));
}

TEST(PointFilter, Attributes) {
  PointFilter f;
  f.classes.emplace();
  f.classes->set(2);
  f.classes->set(6);
  FilterPoint p = at(0, 0, 0);
  p.classification = 2;
  EXPECT_TRUE(passes(f, p));
  p.classification = 3;
  EXPECT_FALSE(passes(f, p));
  p.classification = 6;
  f.intensity = std::pair(100.0, 200.0);
  p.intensity = 200;
  EXPECT_TRUE(passes(f, p));
  p.intensity = 201;
  EXPECT_FALSE(passes(f, p));
  p.intensity = 100;
  f.gpsTime = std::pair(5.5, 6.5);
  p.gpsTime = 5.4;
  EXPECT_FALSE(passes(f, p));
  p.gpsTime = 6.5;
  EXPECT_TRUE(passes(f, p));
  f.sourceIds = std::vector<uint16_t>{1, 4, 7};
  p.pointSourceId = 4;
  EXPECT_TRUE(passes(f, p));
  p.pointSourceId = 5;
  EXPECT_FALSE(passes(f, p));
}

TEST(PointFilter, Returns) {
  struct Case {
    uint8_t rn, nr;
    bool first, last, only;
  };
  const Case cases[] = {{1, 1, true, true, true},   {1, 3, true, false, false},  {2, 3, false, false, false},
                        {3, 3, false, true, false}, {0, 0, false, false, false}, {0, 2, false, false, false}};
  for (const Case& c : cases) {
    FilterPoint p = at(0, 0, 0);
    p.returnNumber = c.rn;
    p.numberOfReturns = c.nr;
    PointFilter f;
    EXPECT_TRUE(passes(f, p));
    f.returns = ReturnFilter::First;
    EXPECT_EQ(passes(f, p), c.first) << int(c.rn) << "/" << int(c.nr);
    f.returns = ReturnFilter::Last;
    EXPECT_EQ(passes(f, p), c.last) << int(c.rn) << "/" << int(c.nr);
    f.returns = ReturnFilter::Only;
    EXPECT_EQ(passes(f, p), c.only) << int(c.rn) << "/" << int(c.nr);
  }
}

TEST(PointFilter, NeedsAndMissingAttributes) {
  PointFilter f;
  f.returns = ReturnFilter::Last;
  FilterNeeds n = filterNeeds(f);
  EXPECT_TRUE(n.returnNumber && n.numberOfReturns);
  EXPECT_FALSE(n.classification || n.intensity || n.gpsTime || n.pointSourceId);
  FilterNeeds has;
  has.returnNumber = true;
  try {
    requireFilterAttributes(f, has, "in.ply");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("in.ply"), std::string::npos) << what;
    EXPECT_NE(what.find("--returns last"), std::string::npos) << what;
    EXPECT_NE(what.find("number of returns"), std::string::npos) << what;
  }
  has.numberOfReturns = true;
  EXPECT_NO_THROW(requireFilterAttributes(f, has, "in.ply"));
  f.gpsTime = std::pair(0.0, 1.0);
  EXPECT_THROW(requireFilterAttributes(f, has, "in.ply"), InputError);
  f.gpsTime.reset();
  f.classes.emplace();
  EXPECT_THROW(requireFilterAttributes(f, has, "in.ply"), InputError);
}

TEST(PointFilter, VerdictsOfBoxes) {
  PointFilter f;
  f.boxes.push_back({{0, 0, 0}, {10, 10, 10}});
  EXPECT_EQ(clipVerdict(f, bounds({1, 1, 1}, {9, 9, 9})), BoxVerdict::All);
  EXPECT_EQ(clipVerdict(f, bounds({11, 1, 1}, {12, 9, 9})), BoxVerdict::None);
  EXPECT_EQ(clipVerdict(f, bounds({5, 5, 5}, {15, 9, 9})), BoxVerdict::Some);
  f.clipMode = ClipMode::Outside;
  EXPECT_EQ(clipVerdict(f, bounds({1, 1, 1}, {9, 9, 9})), BoxVerdict::None);
  EXPECT_EQ(clipVerdict(f, bounds({11, 1, 1}, {12, 9, 9})), BoxVerdict::All);
  f.clipMode = ClipMode::Highlight;
  EXPECT_EQ(clipVerdict(f, bounds({11, 1, 1}, {12, 9, 9})), BoxVerdict::All);
  // A polygon around a box, a box around the polygon, a polygon beside it.
  PointFilter p;
  ClipPolygon tri;
  tri.vertices = {{0, 0}, {100, 0}, {0, 100}};
  p.polygons.push_back(tri);
  EXPECT_EQ(clipVerdict(p, bounds({10, 10, -5}, {20, 20, 5})), BoxVerdict::All);
  EXPECT_EQ(clipVerdict(p, bounds({-10, -10, 0}, {200, 200, 1})), BoxVerdict::Some);
  EXPECT_EQ(clipVerdict(p, bounds({60, 60, 0}, {70, 70, 1})), BoxVerdict::None);
  p.polygons[0].zMin = 0;
  p.polygons[0].zMax = 1;
  EXPECT_EQ(clipVerdict(p, bounds({10, 10, 2}, {20, 20, 3})), BoxVerdict::None);
  EXPECT_EQ(clipVerdict(p, bounds({10, 10, 0.5}, {20, 20, 3})), BoxVerdict::Some);
}

// Whatever the volumes, a verdict of All or None holds for every point of the box (sampled, corners and
// faces included), and boxes that straddle a boundary get Some.
TEST(PointFilter, VerdictsAgreeWithPoints) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  int decided = 0, straddled = 0;
  for (int trial = 0; trial < 300; ++trial) {
    PointFilter f;
    f.clipMode = trial % 2 ? ClipMode::Outside : ClipMode::Inside;
    const glm::dvec3 c(u(rng) * 10, u(rng) * 10, u(rng) * 10);
    const glm::dvec3 h(1 + u(rng) * 3, 1 + u(rng) * 3, 1 + u(rng) * 3);
    if (trial % 3 == 0) f.boxes.push_back({c - h, c + h});
    if (trial % 3 == 1) {
      OrientedClipBox o;
      const double a = u(rng) * 6.28;
      o.center = c;
      o.axes = {glm::dvec3(std::cos(a), std::sin(a), 0), glm::dvec3(-std::sin(a), std::cos(a), 0),
                glm::dvec3(0, 0, 1)};
      o.halfExtent = h;
      f.orientedBoxes.push_back(o);
    }
    if (trial % 3 == 2) {
      ClipPolygon poly;
      for (int k = 0; k < 5; ++k) {
        const double a = k * 6.283185 / 5, r = 2 + 2 * u(rng);
        poly.vertices.emplace_back(c.x + r * std::cos(a), c.y + r * std::sin(a));
      }
      poly.zMin = c.z - h.z;
      poly.zMax = c.z + h.z;
      f.polygons.push_back(poly);
    }
    for (int q = 0; q < 20; ++q) {
      const glm::dvec3 lo(u(rng) * 12 - 1, u(rng) * 12 - 1, u(rng) * 12 - 1);
      const glm::dvec3 size(u(rng) * 4, u(rng) * 4, u(rng) * 4);
      const Bounds box = bounds(lo, lo + size);
      const BoxVerdict v = clipVerdict(f, box);
      int kept = 0, dropped = 0;
      for (int s = 0; s < 200; ++s) {
        glm::dvec3 p = lo + size * glm::dvec3(u(rng), u(rng), u(rng));
        if (s < 8) p = lo + size * glm::dvec3(s & 1, (s >> 1) & 1, (s >> 2) & 1);
        (passes(f, at(p.x, p.y, p.z)) ? kept : dropped)++;
      }
      if (v == BoxVerdict::All) {
        EXPECT_EQ(dropped, 0);
      }
      if (v == BoxVerdict::None) {
        EXPECT_EQ(kept, 0);
      }
      decided += v != BoxVerdict::Some;
      if (kept && dropped) {
        EXPECT_EQ(v, BoxVerdict::Some);
        ++straddled;
      }
    }
  }
  EXPECT_GT(decided, 1000); // the verdicts cull, not just answer Some
  EXPECT_GT(straddled, 100);
}

} // namespace
} // namespace pointrast
