#include "view/camera_path.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "base/error.h"

namespace pointrast::view {
namespace {

Camera cam(glm::dvec3 eye, glm::dvec3 target, double fov = 60) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.fovY = fov;
  return c;
}

CameraPath threeKeyframes() {
  CameraPath p;
  p.append(cam({0, -10, 5}, {0, 0, 0}, 40));
  p.append(cam({10, 0, 5}, {1, 0, 0}, 60), 2.0);
  p.append(cam({0, 10, 5}, {0, 1, 0}, 50), 1.0);
  return p;
}

TEST(CameraPath, SamplesAtKeyframeTimesAreTheKeyframesExactly) {
  CameraPath p = threeKeyframes();
  EXPECT_DOUBLE_EQ(p.duration(), 3.0);
  for (const Keyframe& k : p.keyframes()) {
    Camera c = p.sample(k.time);
    EXPECT_EQ(c.eye, k.camera.eye);
    EXPECT_EQ(c.target, k.camera.target);
    EXPECT_EQ(c.fovY, k.camera.fovY);
  }
  // Clamped outside.
  EXPECT_EQ(p.sample(-1).eye, p.keyframes().front().camera.eye);
  EXPECT_EQ(p.sample(99).eye, p.keyframes().back().camera.eye);
}

TEST(CameraPath, IsContinuousAndInterpolatesBetweenKeyframes) {
  CameraPath p = threeKeyframes();
  // Midway through the first segment the fov is halfway and the eye lies between the keyframes' eyes.
  Camera mid = p.sample(1.0);
  EXPECT_DOUBLE_EQ(mid.fovY, 50);
  // Straight-line keyframes (collinear, evenly timed) give a straight, evenly paced path.
  CameraPath line;
  for (int i = 0; i < 4; ++i)
    line.append(cam({double(i), 0, 0}, {double(i), 1, 0}), 1.0);
  for (double t = 0; t <= 3; t += 0.125) {
    EXPECT_NEAR(line.sample(t).eye.x, t, 1e-12);
    EXPECT_NEAR(line.sample(t).eye.y, 0, 1e-12);
  }
  // No jumps across keyframes.
  for (double t : {1.0, 3.0}) {
    glm::dvec3 a = p.sample(t - 1e-7).eye, b = p.sample(t + 1e-7).eye;
    EXPECT_LT(glm::length(a - b), 1e-4);
  }
}

TEST(CameraPath, FrameCountIncludesBothEnds) {
  CameraPath p = threeKeyframes();
  EXPECT_EQ(p.frameCount(60), 181u);
  EXPECT_EQ(p.frameCount(10), 31u);
  CameraPath one;
  one.append(cam({1, 1, 1}, {0, 0, 0}));
  EXPECT_EQ(one.frameCount(30), 1u);
  EXPECT_EQ(CameraPath().frameCount(30), 0u);
}

TEST(CameraPath, JsonRoundTripIsExact) {
  CameraPath p = threeKeyframes();
  CameraPath& q = p;
  q.append(cam({636001.123456789, 848900.987654321, 700.000001}, {636600.5, 849200.25, 450.125}), 0.3);
  CameraPath back = CameraPath::parse(q.toJson(), "path.json");
  ASSERT_EQ(back.keyframes().size(), q.keyframes().size());
  for (size_t i = 0; i < q.keyframes().size(); ++i) {
    EXPECT_EQ(back.keyframes()[i].time, q.keyframes()[i].time);
    EXPECT_EQ(back.keyframes()[i].camera.eye, q.keyframes()[i].camera.eye);
    EXPECT_EQ(back.keyframes()[i].camera.target, q.keyframes()[i].camera.target);
    EXPECT_EQ(back.keyframes()[i].camera.up, q.keyframes()[i].camera.up);
    EXPECT_EQ(back.keyframes()[i].camera.fovY, q.keyframes()[i].camera.fovY);
  }
}

TEST(CameraPath, SaveAndLoadThroughAFile) {
  auto file =
      std::filesystem::temp_directory_path() / ("pointrast_path_" + std::to_string(::getpid()) + ".json");
  threeKeyframes().save(file);
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".partial"));
  CameraPath back = CameraPath::load(file);
  EXPECT_EQ(back.keyframes().size(), 3u);
  std::filesystem::remove(file);
}

TEST(CameraPath, RefusesBadFilesWithOneClearError) {
  auto refuse = [](const std::string& text, const std::string& words) {
    try {
      CameraPath::parse(text, "p.json");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      std::string what = e.what();
      EXPECT_EQ(what.rfind("p.json", 0), 0u) << what;
      EXPECT_NE(what.find(words), std::string::npos) << what;
    }
  };
  std::string head = R"({"format":"pointrast-camera-path","version":1,"keyframes":)";
  refuse("{", "not a JSON file");
  refuse("[]", "not a camera path");
  refuse(R"({"format":"pointrast-camera-path","version":2,"keyframes":[]})", "version");
  refuse(head + "[]}", "non-empty");
  refuse(head + R"([{"time":0,"eye":[0,1,1],"target":[0,0,0]}, {"time":0,"eye":[0,2,1],"target":[0,0,0]}]})",
         "increase strictly");
  refuse(head + R"([{"time":0,"eye":[0,0,1],"target":[0,0,1]}]})", "must differ");
  refuse(head + R"([{"time":0,"eye":[0,0],"target":[0,0,0]}]})", "\"eye\"");
  refuse(head + R"([{"time":0,"eye":[0,0,"x"],"target":[0,0,0]}]})", "finite");
  refuse(head + R"([{"time":0,"eye":[0,1,1],"target":[0,0,0],"fov":200}]})", "fov");
  refuse(head + R"([{"eye":[0,0,1],"target":[0,0,0]}]})", "\"time\"");
  refuse(head + R"([{"time":0,"eye":[0,0,1e999],"target":[0,0,0]}]})", "");
  EXPECT_THROW(CameraPath::load("/nonexistent/path.json"), InputError);
  EXPECT_THROW(CameraPath::load("/tmp"), InputError);
}

TEST(CameraPath, OrbitTurnsOnceAroundTheTarget) {
  Camera start = cam({10, 0, 5}, {0, 0, 0});
  CameraPath orbit = orbitPath(start, 4.0);
  EXPECT_DOUBLE_EQ(orbit.duration(), 4.0);
  EXPECT_EQ(orbit.sample(0).eye, start.eye);
  // A quarter turn counterclockwise seen from above; between keyframes the spline stays near the circle.
  glm::dvec3 quarter = orbit.sample(1.0).eye;
  EXPECT_NEAR(quarter.x, 0, 1e-9);
  EXPECT_NEAR(quarter.y, 10, 1e-9);
  EXPECT_NEAR(quarter.z, 5, 1e-9);
  for (double t = 0; t <= 4; t += 0.01) {
    glm::dvec3 e = orbit.sample(t).eye;
    EXPECT_NEAR(std::hypot(e.x, e.y), 10, 0.01) << t;
    EXPECT_EQ(orbit.sample(t).target, start.target);
  }
  EXPECT_LT(glm::length(orbit.sample(4.0).eye - start.eye), 1e-9);
}

} // namespace
} // namespace pointrast::view
