// The benchmark's viewpoints, checked on the CPU with the camera contract of docs/design.md: a point lands in
// the image when its clip w exceeds near and its pixel is inside. overview frames the whole cloud,
// closeup keeps a minority of the points, outside none; all of it a function of the bounds alone.
#include <cmath>

#include <gtest/gtest.h>

#include "base/error.h"
#include "bench/views.h"
#include "cloud/generate.h"

namespace {

using namespace pointrast;

constexpr uint32_t kWidth = 320, kHeight = 200;

// Points whose pixel is inside the image, with the renderer's projection (relative to the origin).
uint64_t pointsInImage(const PointCloud& cloud, const Camera& camera) {
  const double aspect = double(kWidth) / kHeight;
  const glm::dvec3 origin = cloud.origin();
  const glm::dmat4 vp = viewProjection(camera, origin, aspect);
  const double nearW = camera.nearW > 0 ? camera.nearW : defaultNear(cloud.bounds);
  uint64_t inside = 0;
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    glm::dvec4 c = vp * glm::dvec4(cloud.world(i) - origin, 1.0);
    if (!(c.w > nearW)) continue;
    double px = std::floor((c.x / c.w + 1) / 2 * kWidth), py = std::floor((1 - c.y / c.w) / 2 * kHeight);
    if (px >= 0 && px < kWidth && py >= 0 && py < kHeight) ++inside;
  }
  return inside;
}

class Views : public ::testing::TestWithParam<Scene> {
protected:
  static PointCloud cloudFor(Scene scene) {
    GenerateOptions options;
    options.points = 100'000;
    options.progress = false;
    return generateScene(scene, options);
  }
};

TEST_P(Views, OverviewFramesEveryPoint) {
  PointCloud cloud = cloudFor(GetParam());
  Camera camera = bench::viewCamera(bench::View::Overview, cloud.bounds, double(kWidth) / kHeight);
  EXPECT_EQ(pointsInImage(cloud, camera), cloud.size());
}

TEST_P(Views, CloseupKeepsAMinorityOfThePoints) {
  PointCloud cloud = cloudFor(GetParam());
  Camera camera = bench::viewCamera(bench::View::Closeup, cloud.bounds, double(kWidth) / kHeight);
  EXPECT_NO_THROW(validateCamera(camera));
  uint64_t inside = pointsInImage(cloud, camera);
  EXPECT_GT(inside, 0u) << "a closeup must still show something";
  EXPECT_LT(inside, cloud.size() / 2) << inside << " of " << cloud.size();
  // The eye is inside the bounds.
  for (int a = 0; a < 3; ++a) {
    EXPECT_GE(camera.eye[a], cloud.bounds.min[a]);
    EXPECT_LE(camera.eye[a], cloud.bounds.max[a]);
  }
}

TEST_P(Views, OutsideShowsNoPoint) {
  PointCloud cloud = cloudFor(GetParam());
  Camera camera = bench::viewCamera(bench::View::Outside, cloud.bounds, double(kWidth) / kHeight);
  EXPECT_NO_THROW(validateCamera(camera));
  EXPECT_EQ(pointsInImage(cloud, camera), 0u);
  // Also with a field of view that would see almost everything in front of the eye.
  camera.fovY = 170;
  EXPECT_EQ(pointsInImage(cloud, camera), 0u);
}

INSTANTIATE_TEST_SUITE_P(Scenes, Views, ::testing::Values(Scene::Terrain, Scene::Tls),
                         [](const auto& p) { return std::string(sceneName(p.param)); });

TEST(ViewsFromBounds, DeterministicAndValidForDegenerateBounds) {
  Bounds box;
  box.expand(glm::dvec3(10, 20, 30));
  box.expand(glm::dvec3(110, 70, 35));
  Bounds point;
  point.expand(glm::dvec3(5, 5, 5));
  for (bench::View v : bench::allViews()) {
    Camera a = bench::viewCamera(v, box, 1.6), b = bench::viewCamera(v, box, 1.6);
    EXPECT_EQ(a.eye, b.eye);
    EXPECT_EQ(a.target, b.target);
    EXPECT_NO_THROW(validateCamera(a)) << bench::viewName(v);
    EXPECT_NO_THROW(validateCamera(bench::viewCamera(v, point, 1.6))) << bench::viewName(v);
  }
}

TEST(ViewsFromBounds, NamesRoundTrip) {
  for (bench::View v : bench::allViews())
    EXPECT_EQ(bench::parseView(bench::viewName(v)), v);
  EXPECT_THROW(bench::parseView("inside"), InputError);
}

} // namespace
