// The GPU side of the session on lavapipe: frames, picking from the framebuffer words, screenshots.
#include "view/scene_view.h"

#include <gtest/gtest.h>

#include "../gpu/gpu_fixture.h"

namespace pointrast::view {
namespace {

using test::GpuTest;

TEST(BoxDownsample, AveragesEachBlockPerChannelRounded) {
  // 4x2 -> 2x1 with factor 2: left block r = (0 + 1 + 2 + 3) / 4 = 1.5 -> 2, right block g = 255.
  std::vector<uint32_t> pixels = {0xFF000000u, 0xFF000001u, 0xFF00FF00u, 0xFF00FF00u,
                                  0xFF000002u, 0xFF000003u, 0xFF00FF00u, 0xFF00FF00u};
  std::vector<uint32_t> out = boxDownsample(pixels, 4, 2, 2);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0], 0xFF000002u);
  EXPECT_EQ(out[1], 0xFF00FF00u);
  EXPECT_EQ(boxDownsample(pixels, 4, 2, 1), pixels);
}

class SceneViewTest : public GpuTest {
protected:
  // Three points in front of a camera looking along +y: one near the image center (inside a pixel, not
  // on a border, where the batch methods' quantization could move it across), one up-left, one twice as
  // far on the first one's line of sight (hidden by it).
  PointCloud cloud = test::cloudFromPoints({{0.05, 10, 0.07}, {-2, 10, 1.5}, {0.1, 20, 0.14}},
                                           {0xFF0000FFu, 0xFF00FF00u, 0xFFFF0000u});
  Camera camera() const {
    Camera c;
    c.eye = {0, 0, 0};
    c.target = {0, 1, 0};
    c.fovY = 90;
    return c;
  }
  Viewport viewport{64, 48};
};

TEST_F(SceneViewTest, PicksTheClosestPointUnderTheCursor) {
  GpuCloud gpuCloud(*context, cloud, false);
  SceneView view(*context, gpuCloud);
  ViewSettings settings;
  for (const char* name : {"atomicmin", "batch", "hqs", "hw-points"}) {
    SCOPED_TRACE(name);
    settings.method = parseMethod(name);
    glm::dvec3 center = project(camera(), viewport, {0.05, 10, 0.07});
    auto hit = view.pick(camera(), settings, viewport, {center.x, center.y});
    ASSERT_TRUE(hit);
    // The pivot is the hit pixel's center at the point's depth: within half a pixel's footprint.
    double footprint = 2 * 10 * std::tan(glm::radians(45.0)) / viewport.height;
    EXPECT_LE(glm::length(*hit - glm::dvec3(0.05, 10, 0.07)), footprint);
    // Two pixels away the nearest point is still found; far from every point nothing is.
    auto near = view.pick(camera(), settings, viewport, {center.x + 2, center.y});
    ASSERT_TRUE(near);
    // The batch methods' adaptive precision moves points by less than half a pixel (and depths by about a
    // thousandth of the bounds here): 0.02 covers it.
    EXPECT_NEAR(near->y, 10, 0.02);
    EXPECT_FALSE(view.pick(camera(), settings, viewport, {2, 45}));
    EXPECT_FALSE(view.pick(camera(), settings, viewport, {-1, 5})) << "outside the viewport";
    auto depth = view.depthAt(camera(), settings, viewport, {center.x, center.y});
    ASSERT_TRUE(depth);
    EXPECT_NEAR(*depth, 10, 0.02);
    // The renderer shows the current method's image again.
    EXPECT_EQ(view.renderer().image(), view.screenshot(camera(), settings, viewport, 1));
  }
}

TEST_F(SceneViewTest, ThePickToolReturnsTheClosestPointWithItsAttributes) {
  cloud.intensity = {100, 200, 300};
  cloud.classification = {2, 6, 9};
  GpuCloud gpuCloud(*context, cloud, false);
  SceneView view(*context, gpuCloud);
  ViewSettings settings;
  for (const char* name : {"atomicmin", "batch", "hqs"}) {
    SCOPED_TRACE(name);
    settings.method = parseMethod(name);
    const glm::dvec3 center = project(camera(), viewport, {0.05, 10, 0.07});
    // On the point's pixel and one pixel beside it: the front point (index 0), not the one behind it.
    for (double dx : {0.0, 1.0}) {
      nlohmann::json j = view.pickAttributes(camera(), settings, viewport, {center.x + dx, center.y});
      ASSERT_TRUE(j["point"].is_object()) << j.dump();
      EXPECT_EQ(j["point"]["index"], 0);
      EXPECT_EQ(j["point"]["intensity"], 100);
      EXPECT_EQ(j["point"]["classification"], 2);
      EXPECT_EQ(j["point"]["color"], nlohmann::json::array({255, 0, 0}));
      EXPECT_NEAR(j["point"]["x"].get<double>(), 0.05, 1e-6);
      EXPECT_NEAR(j["world"][1].get<double>(), 10, 1e-6);
      EXPECT_EQ(j["pixel"], nlohmann::json::array({int(center.x), int(center.y)}));
    }
    EXPECT_EQ(view.pickAttributes(camera(), settings, viewport, {2, 45})["point"], "none");
    EXPECT_EQ(view.pickAttributes(camera(), settings, viewport, {-1, 5})["point"], "none");
  }
  settings.method = parseMethod("batch"); // a method that draws stereo
  settings.stereo = true;
  const nlohmann::json stereo = view.pickAttributes(camera(), settings, viewport, {32, 24})["point"];
  ASSERT_TRUE(stereo.is_string()) << stereo.dump();
  EXPECT_EQ(stereo.get<std::string>().rfind("unavailable: ", 0), 0u) << stereo;
}

TEST_F(SceneViewTest, FramesAndScreenshots) {
  GpuCloud gpuCloud(*context, cloud, false);
  SceneView view(*context, gpuCloud);
  ViewSettings settings;
  FrameReport report = view.render(camera(), settings, viewport);
  EXPECT_EQ(report.points, 3u);
  EXPECT_GT(report.gpuBytes, 0u);
  EXPECT_EQ(view.renderer().width(), 64u);
  std::vector<uint32_t> one = view.renderer().image();
  glm::dvec3 center = project(camera(), viewport, {0.05, 10, 0.07});
  EXPECT_EQ(one[size_t(center.y) * 64 + size_t(center.x)], 0xFF0000FFu) << "the near point hides the far one";
  // Supersampled: the 2x render box-filtered down.
  Renderer big(*context, 128, 96);
  big.render(gpuCloud.scene(SceneLayout::Float), camera(), renderSettings(settings));
  std::vector<uint32_t> bigPixels = big.image();
  EXPECT_EQ(view.screenshot(camera(), settings, viewport, 2), boxDownsample(bigPixels, 128, 96, 2));
  // A resize makes a renderer of the new size.
  view.render(camera(), settings, {32, 32});
  EXPECT_EQ(view.renderer().width(), 32u);
  EXPECT_FALSE(view.changedSinceLastFrame());
  // A second view of the same cloud (another client of the browser viewer) shares its uploads.
  uint64_t uploaded = gpuCloud.bytes();
  SceneView other(*context, gpuCloud);
  other.render(camera(), settings, {16, 16});
  EXPECT_EQ(gpuCloud.bytes(), uploaded);
  EXPECT_EQ(other.renderer().width(), 16u);
  EXPECT_EQ(view.renderer().width(), 32u);
}

} // namespace
} // namespace pointrast::view
