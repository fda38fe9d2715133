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

} // namespace
} // namespace pointrast::view
