// Camera navigation without a cloud or a window: exact expectations from geometry.
#include "view/navigation.h"

#include <cmath>

#include <gtest/gtest.h>

namespace pointrast::view {
namespace {

constexpr double kPi = 3.14159265358979323846;

void expectNear(const glm::dvec3& a, const glm::dvec3& b, double tolerance = 1e-9) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

Camera lookingAlongY() {
  Camera c;
  c.eye = {0, -10, 0};
  c.target = {0, 0, 0};
  c.up = {0, 0, 1};
  c.fovY = 90; // tan(45 deg) = 1: one pixel row spans 2 d / height at depth d
  return c;
}

Bounds unitCube() {
  Bounds b;
  b.expand(glm::dvec3(-1));
  b.expand(glm::dvec3(1));
  return b;
}

TEST(Navigation, PixelRayThroughTheCenterIsTheViewDirection) {
  Viewport vp{200, 100};
  expectNear(pixelRay(lookingAlongY(), vp, {100, 50}), {0, 1, 0});
  // The top-right corner with fov 90 and aspect 2: right * 2 + up * 1.
  expectNear(pixelRay(lookingAlongY(), vp, {200, 0}), {2, 1, 1});
}

TEST(Navigation, ProjectInvertsUnproject) {
  Viewport vp{640, 480};
  Camera c = lookingAlongY();
  c.eye = {3, -7, 2};
  glm::dvec3 p = unproject(c, vp, {123.5, 77.25}, 4.5);
  glm::dvec3 back = project(c, vp, p);
  EXPECT_NEAR(back.x, 123.5, 1e-9);
  EXPECT_NEAR(back.y, 77.25, 1e-9);
  EXPECT_NEAR(back.z, 4.5, 1e-9);
}

TEST(Navigation, ProjectAgreesWithTheRendererMatrix) {
  // docs/design.md: px = (x/w + 1)/2 * W, py = (1 - y/w)/2 * H from viewProjection.
  Viewport vp{320, 240};
  Camera c = lookingAlongY();
  c.eye = {1, -5, 2};
  c.target = {0.5, 1, 0};
  c.fovY = 50;
  glm::dvec3 p{0.3, 2, -0.4};
  glm::dvec4 clip = viewProjection(c, glm::dvec3(0), vp.aspect()) * glm::dvec4(p, 1);
  glm::dvec3 ours = project(c, vp, p);
  EXPECT_NEAR(ours.x, (clip.x / clip.w + 1) / 2 * vp.width, 1e-9);
  EXPECT_NEAR(ours.y, (1 - clip.y / clip.w) / 2 * vp.height, 1e-9);
  EXPECT_NEAR(ours.z, clip.w, 1e-9);
}

TEST(Navigation, OrbitYawTurnsAroundTheVerticalThroughThePivot) {
  Camera c;
  c.eye = {10, 0, 0};
  c.target = {0, 0, 0};
  Camera turned = orbit(c, {0, 0, 0}, {0, 0, 1}, kPi / 2, 0);
  expectNear(turned.eye, {0, 10, 0});
  expectNear(turned.target, {0, 0, 0});
  // Around another pivot the target turns too.
  turned = orbit(c, {5, 0, 0}, {0, 0, 1}, kPi, 0);
  expectNear(turned.eye, {0, 0, 0});
  expectNear(turned.target, {10, 0, 0});
}

TEST(Navigation, OrbitPitchRaisesTheViewAndClampsTheElevation) {
  Camera c;
  c.eye = {0, -10, 0};
  c.target = {0, 0, 0};
  // Pitch -30 deg lowers the view direction: the eye rises to 10 sin 30 above the pivot.
  Camera down = orbit(c, {0, 0, 0}, {0, 0, 1}, 0, -kPi / 6);
  expectNear(down.eye, {0, -10 * std::cos(kPi / 6), 10 * std::sin(kPi / 6)});
  // Far past straight down: clamped at 89.5 degrees of elevation.
  Camera clamped = orbit(c, {0, 0, 0}, {0, 0, 1}, 0, -kPi);
  double elevation = std::asin(glm::normalize(clamped.target - clamped.eye).z);
  EXPECT_NEAR(elevation, -glm::radians(kMaxElevationDegrees), 1e-12);
  EXPECT_NEAR(glm::length(clamped.eye), 10, 1e-9);
  EXPECT_NO_THROW(validateCamera(clamped));
}

TEST(Navigation, OrbitDragOfHalfTheHeightTurnsNinetyDegrees) {
  Camera c;
  c.eye = {10, 0, 0};
  c.target = {0, 0, 0};
  Navigation nav(unitCube(), c);
  Viewport vp{800, 600};
  nav.beginDrag(DragMode::Orbit, {400, 300});
  // Intermediate events do not matter: only the total offset does.
  nav.drag({437, 300}, vp);
  nav.drag({100, 300}, vp);
  EXPECT_TRUE(nav.drag({100, 300}, vp) == false);
  nav.drag({700, 300}, vp);
  nav.endDrag();
  // +300 px = half the height = 90 degrees; dragging right turns the camera clockwise from above.
  expectNear(nav.camera().eye, {0, -10, 0});
}

TEST(Navigation, PanKeepsThePointUnderTheCursorAtThePivotDepth) {
  Camera c = lookingAlongY();
  Navigation nav(unitCube(), c);
  Viewport vp{400, 400};
  nav.beginDrag(DragMode::Pan, {200, 200});
  nav.drag({250, 180}, vp);
  // fov 90, depth 10, 400 px: 0.05 units a pixel. The scene moves with the cursor: the camera opposite.
  expectNear(nav.camera().eye, {-2.5, -10, -1});
  expectNear(nav.camera().target, {-2.5, 0, -1});
  expectNear(nav.pivot(), {-2.5, 0, -1});
  // The point that was under the cursor at the start is under it now.
  glm::dvec3 p = project(nav.camera(), vp, {0, 0, 0});
  EXPECT_NEAR(p.x, 250, 1e-9);
  EXPECT_NEAR(p.y, 180, 1e-9);
}

TEST(Navigation, ZoomScalesTowardsThePointUnderTheCursor) {
  Camera c = lookingAlongY();
  Navigation nav(unitCube(), c);
  Viewport vp{400, 400};
  glm::dvec3 under = unproject(c, vp, {300, 100}, 10);
  nav.zoom({300, 100}, 1, vp);
  expectNear(nav.camera().eye, under + (c.eye - under) * kZoomPerStep);
  glm::dvec3 p = project(nav.camera(), vp, under);
  EXPECT_NEAR(p.x, 300, 1e-9);
  EXPECT_NEAR(p.y, 100, 1e-9);
  EXPECT_NEAR(p.z, 10 * kZoomPerStep, 1e-9);
  // With a depth read from the framebuffer the zoom goes towards that point instead.
  Navigation picked(unitCube(), c);
  picked.zoom({200, 200}, -2, vp, 4.0);
  expectNear(picked.camera().eye,
             glm::dvec3(0, -6, 0) + glm::dvec3(0, -4, 0) / (kZoomPerStep * kZoomPerStep));
}

TEST(Navigation, FlyMovesAtAFractionOfTheDiagonalPerSecond) {
  Camera c = lookingAlongY();
  Navigation nav(unitCube(), c); // diagonal 2 sqrt 3
  FlyInput in;
  in.forward = 1;
  in.up = -1;
  EXPECT_TRUE(nav.fly(in, 0.5));
  double d = 2 * std::sqrt(3.0) * kFlyDiagonalsPerSecond * 0.5;
  expectNear(nav.camera().eye, {0, -10 + d, -d});
  in.fast = true;
  in.up = 0;
  in.forward = 0;
  in.right = 1;
  nav.fly(in, 1);
  expectNear(nav.camera().eye, {d * 2 * kFlyFastFactor, -10 + d, -d});
  EXPECT_FALSE(nav.fly(FlyInput{}, 1));
}

TEST(Navigation, AxisViewsLookAtTheCenterAndHoldTheBounds) {
  Bounds b;
  b.expand(glm::dvec3(10, 20, 0));
  b.expand(glm::dvec3(30, 60, 5));
  Viewport vp{800, 600};
  Navigation nav(b, lookingAlongY());
  struct Case {
    StandardView view;
    glm::dvec3 forward;
  } cases[] = {{StandardView::Top, {0, 0, -1}},  {StandardView::Bottom, {0, 0, 1}},
               {StandardView::Front, {0, 1, 0}}, {StandardView::Back, {0, -1, 0}},
               {StandardView::Left, {1, 0, 0}},  {StandardView::Right, {-1, 0, 0}}};
  for (const Case& k : cases) {
    nav.viewFrom(k.view, vp);
    const Camera& c = nav.camera();
    SCOPED_TRACE(standardViewName(k.view));
    expectNear(c.target, b.center());
    expectNear(nav.pivot(), b.center());
    expectNear(glm::normalize(c.target - c.eye), k.forward);
    EXPECT_NO_THROW(validateCamera(c));
    for (int i = 0; i < 8; ++i) {
      glm::dvec3 corner{i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z};
      glm::dvec3 p = project(c, vp, corner);
      EXPECT_GT(p.z, 0);
      EXPECT_GE(p.x, 0);
      EXPECT_LE(p.x, vp.width);
      EXPECT_GE(p.y, 0);
      EXPECT_LE(p.y, vp.height);
    }
  }
  // The top view has north (+y) up in the image.
  nav.viewFrom(StandardView::Top, vp);
  EXPECT_LT(project(nav.camera(), vp, {20, 59, 2.5}).y, vp.height / 2.0);
  // Orbiting away from straight down works and returns to z up.
  nav.beginDrag(DragMode::Orbit, {0, 0});
  nav.drag({10, 30}, vp);
  EXPECT_EQ(nav.camera().up, glm::dvec3(0, 0, 1));
  EXPECT_NO_THROW(validateCamera(nav.camera()));
}

TEST(Navigation, FrameAllKeepsTheDirectionAndMatchesTheOverview) {
  Bounds b = unitCube();
  Viewport vp{640, 480};
  Camera overview = overviewCamera(b, vp.aspect());
  Camera away = overview;
  // The same direction, seven times as far, from elsewhere.
  away.eye = overview.target + 7.0 * (overview.eye - overview.target) + glm::dvec3(3, 3, 3);
  away.target = overview.target + glm::dvec3(3, 3, 3);
  Navigation nav(b, away);
  nav.frameAll(vp);
  expectNear(nav.camera().eye, overview.eye);
  expectNear(nav.camera().target, overview.target);
}

} // namespace
} // namespace pointrast::view
