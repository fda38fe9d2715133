#include "view/motion.h"

namespace pointrast::view {

bool MotionQuality::changed(const Camera& camera) const {
  if (!last_) return true;
  return camera.eye != last_->eye || camera.target != last_->target || camera.up != last_->up ||
         camera.fovY != last_->fovY || camera.nearW != last_->nearW;
}

FrameQuality MotionQuality::next(const Camera& camera, double now) const {
  if (!last_ || !changed(camera)) return FrameQuality::Full;
  return now - lastChange_ < kRestSeconds ? FrameQuality::Motion : FrameQuality::Full;
}

void MotionQuality::rendered(const Camera& camera, FrameQuality quality, double now) {
  if (changed(camera)) lastChange_ = now;
  last_ = camera;
  lastQuality_ = quality;
}

bool MotionQuality::refineDue(double now) const {
  return lastQuality_ == FrameQuality::Motion && now - lastChange_ >= kRestSeconds;
}

std::optional<double> MotionQuality::refineAt() const {
  if (lastQuality_ != FrameQuality::Motion) return std::nullopt;
  return lastChange_ + kRestSeconds;
}

} // namespace pointrast::view
