// The viewers' measuring tool: vertices from picks, the kinds, deletion, and the list the panels show.
#include "view/measure_tool.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/annotations_file.h"

namespace pointrast::view {
namespace {

TEST(MeasureTool, PicksBecomeVerticesOfTheOpenMeasurement) {
  MeasureTool tool;
  tool.add(AnnotationKind::Distance, {0, 0, 0});
  ASSERT_EQ(tool.all().items.size(), 1u);
  EXPECT_EQ(tool.complete().items.size(), 0u) << "one point measures nothing yet";
  tool.add(AnnotationKind::Distance, {3, 4, 0});
  tool.add(AnnotationKind::Distance, {3, 4, 12});
  nlohmann::json list = nlohmann::json::parse(tool.json());
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0]["type"], "distance");
  EXPECT_EQ(list[0]["open"], true);
  EXPECT_EQ(list[0]["segments"], nlohmann::json::array({5.0, 12.0}));
  EXPECT_DOUBLE_EQ(list[0]["value"].get<double>(), 17.0);
  EXPECT_EQ(list[0]["text"], "17.00");
  // Another kind starts a new measurement; a height closes itself at its second point.
  tool.add(AnnotationKind::Height, {0, 0, 1});
  tool.add(AnnotationKind::Height, {10, 0, 4});
  EXPECT_FALSE(tool.open());
  tool.add(AnnotationKind::Height, {0, 0, 0});
  list = nlohmann::json::parse(tool.json());
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[0]["open"], false);
  EXPECT_DOUBLE_EQ(list[1]["value"].get<double>(), 3.0);
  EXPECT_TRUE(list[2].contains("problem"));
  // Finishing drops an open measurement that cannot be measured.
  tool.finish();
  EXPECT_EQ(tool.all().items.size(), 2u);
}

TEST(MeasureTool, AnAreaClosesItsOutlineAndDeletionRenumbers) {
  MeasureTool tool;
  tool.add(AnnotationKind::Distance, {0, 0, 0});
  tool.add(AnnotationKind::Distance, {1, 0, 0});
  tool.finish();
  for (glm::dvec3 p : {glm::dvec3(0, 0, 0), glm::dvec3(4, 0, 0), glm::dvec3(4, 3, 0)})
    tool.add(AnnotationKind::Area, p);
  nlohmann::json list = nlohmann::json::parse(tool.json());
  ASSERT_EQ(list.size(), 2u);
  EXPECT_DOUBLE_EQ(list[1]["value"].get<double>(), 6.0);
  EXPECT_EQ(list[1]["segments"], nlohmann::json::array({4.0, 3.0, 5.0}));
  const uint64_t version = tool.version();
  EXPECT_TRUE(tool.remove(0));
  EXPECT_GT(tool.version(), version);
  EXPECT_FALSE(tool.remove(5));
  ASSERT_EQ(tool.all().items.size(), 1u);
  EXPECT_EQ(tool.open(), 0u) << "the open area moved to index 0";
  tool.add(AnnotationKind::Area, {0, 3, 0});
  EXPECT_EQ(tool.all().items[0].points.size(), 4u);
  tool.clear();
  EXPECT_TRUE(tool.all().items.empty());
}

TEST(MeasureTool, AVertexNearAPositionMovesAndTheValueFollows) {
  MeasureTool tool;
  tool.add(AnnotationKind::Distance, {0, 0, 0});
  tool.add(AnnotationKind::Distance, {10, 0, 0});
  tool.finish();
  // Looking down the -z axis from 20 units above the origin: x to the right, y up, a 90 degree view of a
  // 200 x 200 image, so that 1 unit at depth 20 is 100 / 20 = 5 pixels.
  Camera camera;
  camera.eye = {0, 0, 20};
  camera.target = {0, 0, 0};
  camera.up = {0, 1, 0};
  camera.fovY = 90;
  const auto first = tool.vertexNear(camera, 0.1, 200, 200, {100.5, 100.5}, 8);
  ASSERT_TRUE(first);
  EXPECT_EQ(*first, std::make_pair(size_t(0), size_t(0)));
  // (10, 0, 0) is drawn 50 pixels right of the centre.
  const auto second = tool.vertexNear(camera, 0.1, 200, 200, {147, 102}, 8);
  ASSERT_TRUE(second);
  EXPECT_EQ(*second, std::make_pair(size_t(0), size_t(1)));
  EXPECT_FALSE(tool.vertexNear(camera, 0.1, 200, 200, {125, 100}, 8)) << "between the two, farther than 8 px";
  // Behind the camera: not seen.
  Camera away = camera;
  away.target = {0, 0, 40};
  EXPECT_FALSE(tool.vertexNear(away, 0.1, 200, 200, {100.5, 100.5}, 8));
  const uint64_t version = tool.version();
  ASSERT_TRUE(tool.move(0, 1, {0, 0, 5}));
  EXPECT_GT(tool.version(), version);
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(tool.json())[0]["value"].get<double>(), 5.0);
  EXPECT_FALSE(tool.move(0, 2, {0, 0, 0}));
  EXPECT_FALSE(tool.move(1, 0, {0, 0, 0}));
}

TEST(MeasureTool, SavedMeasurementsLoadBackTheSame) {
  MeasureTool tool;
  tool.add(AnnotationKind::Distance, {636000.125, 849000.5, 420.25});
  tool.add(AnnotationKind::Distance, {636010.0, 849003.75, 421.0});
  tool.add(AnnotationKind::Area, {0, 0, 0}); // open with one point: not saved
  const Annotations saved = tool.complete();
  ASSERT_EQ(saved.items.size(), 1u);
  MeasureTool loaded;
  loaded.load(io::parseAnnotations(io::annotationsJson(saved), "test"));
  MeasureTool direct;
  direct.load(saved);
  EXPECT_EQ(loaded.json(), direct.json());
  EXPECT_EQ(loaded.all().items[0].points, saved.items[0].points);
}

} // namespace
} // namespace pointrast::view
