// Motion frames while the camera keeps moving, one full frame once it rests.
#include "view/motion.h"

#include <gtest/gtest.h>

namespace pointrast::view {
namespace {

Camera at(double x) {
  Camera c;
  c.eye = {x, -10, 0};
  c.target = {0, 0, 0};
  return c;
}

TEST(MotionQuality, ContinuousChangesAreMotionAndRestIsFull) {
  MotionQuality q;
  EXPECT_EQ(q.next(at(0), 0.0), FrameQuality::Full); // the first frame
  q.rendered(at(0), FrameQuality::Full, 0.0);
  EXPECT_FALSE(q.refineAt());
  // A discrete change long after the last one: full at once.
  EXPECT_EQ(q.next(at(1), 5.0), FrameQuality::Full);
  q.rendered(at(1), FrameQuality::Full, 5.0);
  // Changes within kRestSeconds of each other: a drag, a burst of wheel steps.
  EXPECT_EQ(q.next(at(2), 5.05), FrameQuality::Motion);
  q.rendered(at(2), FrameQuality::Motion, 5.05);
  EXPECT_EQ(q.next(at(3), 5.1), FrameQuality::Motion);
  q.rendered(at(3), FrameQuality::Motion, 5.1);
  EXPECT_FALSE(q.refineDue(5.1 + kRestSeconds / 2));
  ASSERT_TRUE(q.refineAt());
  EXPECT_DOUBLE_EQ(*q.refineAt(), 5.1 + kRestSeconds);
  EXPECT_TRUE(q.refineDue(5.1 + kRestSeconds));
  // The refinement: the same camera, full.
  EXPECT_EQ(q.next(at(3), 5.4), FrameQuality::Full);
  q.rendered(at(3), FrameQuality::Full, 5.4);
  EXPECT_FALSE(q.refineDue(10.0));
  EXPECT_FALSE(q.refineAt());
}

TEST(MotionQuality, ASettingsChangeWithTheSameCameraIsFull) {
  MotionQuality q;
  q.rendered(at(0), FrameQuality::Full, 0.0);
  q.rendered(at(1), FrameQuality::Motion, 0.05);
  EXPECT_EQ(q.next(at(1), 0.06), FrameQuality::Full);
}

// Frames slower than kRestSeconds (a large canvas on lavapipe): the drag's inputs, 8 ms apart, say the camera
// keeps moving; without them every frame would look like one after a rest and be a full one.
TEST(MotionQuality, ADragStaysMotionWhenFramesAreSlowerThanTheRest) {
  MotionQuality q;
  q.rendered(at(0), FrameQuality::Full, 0.0);
  q.input(10.0); // the first move after a pause: a discrete change
  EXPECT_EQ(q.next(at(1), 10.0), FrameQuality::Full);
  q.rendered(at(1), FrameQuality::Full, 10.0);
  for (int i = 1; i <= 60; ++i)
    q.input(10.0 + 0.008 * i);
  // The next frame, 0.5 s later: the inputs kept coming until just before it.
  EXPECT_EQ(q.next(at(2), 10.5), FrameQuality::Motion);
  q.rendered(at(2), FrameQuality::Motion, 10.5);
  EXPECT_FALSE(q.refineDue(10.5));
  // The drag stopped at 10.48: the full frame follows kRestSeconds after the last input or frame.
  ASSERT_TRUE(q.refineAt());
  EXPECT_DOUBLE_EQ(*q.refineAt(), 10.5 + kRestSeconds);
  EXPECT_TRUE(q.refineDue(10.75));
  // A lone wheel step long after: full at once.
  q.rendered(at(2), FrameQuality::Full, 10.8);
  q.input(20.0);
  EXPECT_EQ(q.next(at(3), 20.1), FrameQuality::Full);
}

// A drag over an octree: between two moves, nodes arrive and a frame is drawn with the camera of the last
// one. While the moves continue it is a motion frame (a full frame's JPEG held up the inputs behind it);
// once they stop, the refinement is full.
TEST(MotionQuality, NewContentDuringADragIsMotionAndAtRestFull) {
  MotionQuality q;
  q.rendered(at(0), FrameQuality::Full, 0.0);
  double t = 1.0;
  for (int i = 1; i <= 10; ++i, t += 0.008) {
    q.input(t);
    EXPECT_EQ(q.next(at(i), t), i == 1 ? FrameQuality::Full : FrameQuality::Motion) << i;
    q.rendered(at(i), q.next(at(i), t), t);
  }
  // Nodes arrived 4 ms after the last move: the same camera, drawn again.
  EXPECT_EQ(q.next(at(10), t + 0.004), FrameQuality::Motion);
  q.rendered(at(10), FrameQuality::Motion, t + 0.004);
  // The drag ended: after kRestSeconds the full frame is due, and new content at rest is full at once.
  EXPECT_TRUE(q.refineDue(t + kRestSeconds));
  EXPECT_EQ(q.next(at(10), t + kRestSeconds), FrameQuality::Full);
}

TEST(MotionQuality, SameCameraComparesEveryField) {
  Camera a = at(1), b = at(1);
  EXPECT_TRUE(sameCamera(a, b));
  b.fovY = 50;
  EXPECT_FALSE(sameCamera(a, b));
  b = a;
  b.up = {0, 1, 0};
  EXPECT_FALSE(sameCamera(a, b));
}

} // namespace
} // namespace pointrast::view
