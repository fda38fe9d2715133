// The session's "when to render" and input handling, without a window.
#include "view/session.h"

#include <utility>

#include <gtest/gtest.h>

namespace pointrast::view {
namespace {

Bounds cube() {
  Bounds b;
  b.expand(glm::dvec3(-1));
  b.expand(glm::dvec3(1));
  return b;
}

Camera start() {
  Camera c;
  c.eye = {0, -10, 0};
  c.target = {0, 0, 0};
  return c;
}

void render(Session& s) {
  ASSERT_TRUE(s.needsFrame());
  s.frameRendered({});
  ASSERT_FALSE(s.needsFrame());
}

struct Streaming : ContentSource {
  bool arrived = false;
  bool changedSinceLastFrame() override { return std::exchange(arrived, false); }
};

TEST(Session, RendersOnlyWhenSomethingChanged) {
  Session s(cube(), start(), {640, 480});
  render(s);
  // A click without motion, a settings write of the same values, a second resize to the same size: no frame.
  s.mouseDown(MouseButton::Left, {10, 10});
  s.mouseUp(MouseButton::Left, {10, 10});
  s.setSettings(s.settings());
  s.resize({640, 480});
  EXPECT_FALSE(s.needsFrame());
  // Each of these does.
  s.mouseDown(MouseButton::Left, {10, 10});
  s.mouseMove({20, 10});
  render(s);
  s.mouseUp(MouseButton::Left, {20, 10});
  EXPECT_FALSE(s.needsFrame());
  ViewSettings other = s.settings();
  other.background = 0xFFFFFFFFu;
  s.setSettings(other);
  render(s);
  s.resize({800, 600});
  render(s);
  s.wheel({5, 5}, 1);
  render(s);
  s.keyDown(Key::FrameAll);
  render(s);
  s.keyDown(Key::ViewTop);
  render(s);
  Streaming streaming;
  s.setContentSource(&streaming);
  EXPECT_FALSE(s.needsFrame());
  streaming.arrived = true;
  render(s);
}

TEST(Session, FlyKeysAnimateWhileHeld) {
  Session s(cube(), start(), {640, 480});
  render(s);
  s.keyDown(Key::Forward, /*shift=*/false);
  EXPECT_TRUE(s.animating());
  EXPECT_TRUE(s.advance(0.05));
  EXPECT_GT(s.camera().eye.y, -10);
  s.keyDown(Key::Back);
  EXPECT_FALSE(s.advance(0.05)) << "forward and back cancel";
  s.keyUp(Key::Forward);
  s.keyUp(Key::Back);
  EXPECT_FALSE(s.animating());
  s.frameRendered({});
  EXPECT_FALSE(s.needsFrame());
}

TEST(Session, DoubleClickAsksForAPickAndSetsThePivot) {
  Session s(cube(), start(), {640, 480});
  s.doubleClick({100, 200});
  Requests r = s.takeRequests();
  ASSERT_TRUE(r.pick);
  EXPECT_EQ(*r.pick, glm::dvec2(100, 200));
  EXPECT_FALSE(s.takeRequests().pick) << "taken once";
  s.pivotPicked(glm::dvec3(0.5, 0.25, 0));
  EXPECT_EQ(s.pivot(), glm::dvec3(0.5, 0.25, 0));
  s.pivotPicked(std::nullopt); // an empty pixel keeps the pivot
  EXPECT_EQ(s.pivot(), glm::dvec3(0.5, 0.25, 0));
}

TEST(Session, KeysMakeRequestsAndKeyframes) {
  Session s(cube(), start(), {640, 480});
  s.keyDown(Key::Screenshot);
  s.keyDown(Key::PrintCamera);
  Requests r = s.takeRequests();
  EXPECT_TRUE(r.screenshot);
  EXPECT_TRUE(r.printCamera);
  EXPECT_FALSE(r.quit);
  s.keyDown(Key::Keyframe);
  s.options().keyframeSeconds = 0.5;
  s.wheel({320, 240}, 1);
  s.keyDown(Key::Keyframe);
  ASSERT_EQ(s.path().keyframes().size(), 2u);
  EXPECT_EQ(s.path().keyframes()[1].time, 0.5);
  EXPECT_EQ(s.path().keyframes()[0].camera.eye, start().eye);
  bool panel = s.options().panel;
  s.keyDown(Key::TogglePanel);
  EXPECT_NE(s.options().panel, panel);
}

TEST(Session, StatisticsAreMediansOfRecentFrames) {
  Session s(cube(), start(), {640, 480});
  for (int i = 1; i <= 5; ++i) {
    FrameReport r;
    r.renderMs = i;
    r.points = 100;
    s.frameRendered(r);
  }
  EXPECT_EQ(s.statistics().frames, 5u);
  EXPECT_DOUBLE_EQ(s.statistics().renderMs, 3);
  EXPECT_EQ(s.statistics().points, 100u);
}

} // namespace
} // namespace pointrast::view
