#include "view/motion.h"

#include <algorithm>

namespace pointrast::view {

bool sameCamera(const Camera& a, const Camera& b) {
  return a.eye == b.eye && a.target == b.target && a.up == b.up && a.fovY == b.fovY && a.nearW == b.nearW;
}

bool MotionQuality::changed(const Camera& camera) const {
  return !last_ || !sameCamera(camera, *last_);
}

void MotionQuality::input(double time) {
  inputsContinue_ = time - lastInput_ < kRestSeconds;
  lastInput_ = std::max(lastInput_, time);
}

FrameQuality MotionQuality::next(const Camera& camera, double now) const {
  if (!last_) return FrameQuality::Full;
  const bool inputsMove = inputsContinue_ && now - lastInput_ < kRestSeconds;
  // The same camera: a settings change at rest shows at full quality at once. While the user's inputs
  // still move the camera, a frame drawn because the content changed under it (level-of-detail nodes
  // arrived) stays a motion frame: a full frame's encoding and decoding would hold up the inputs behind it.
  if (!changed(camera)) return inputsMove ? FrameQuality::Motion : FrameQuality::Full;
  const bool framesMove = now - lastChange_ < kRestSeconds;
  return framesMove || inputsMove ? FrameQuality::Motion : FrameQuality::Full;
}

void MotionQuality::rendered(const Camera& camera, FrameQuality quality, double now) {
  if (changed(camera)) lastChange_ = now;
  last_ = camera;
  lastQuality_ = quality;
}

// Rest: neither a frame nor an input changed the camera for kRestSeconds.
bool MotionQuality::refineDue(double now) const {
  return lastQuality_ == FrameQuality::Motion && now - std::max(lastChange_, lastInput_) >= kRestSeconds;
}

std::optional<double> MotionQuality::refineAt() const {
  if (lastQuality_ != FrameQuality::Motion) return std::nullopt;
  return std::max(lastChange_, lastInput_) + kRestSeconds;
}

} // namespace pointrast::view
