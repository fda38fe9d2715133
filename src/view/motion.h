// Frames while the camera moves and the refined frame once it rests, for front ends that pay for every
// pixel they send (the browser viewer streams JPEG): while the camera moves, frames may be cheaper (fewer
// pixels, lower JPEG quality); once it has rested for kRestSeconds, one full frame replaces the last
// cheap one. A single discrete change (a view key, one wheel step after a pause, a settings change) gets a
// full frame at once: only a camera that keeps changing is "moving", judged by its frames and, where frames
// are slower than kRestSeconds (a large canvas on a slow device, a client slow to take frames), by the
// inputs that move it: without that, every frame of a slow drag would look like one after a rest and be
// the costliest kind. Times are seconds on any monotonic clock, passed in, so the policy is tested without
// waiting.
#pragma once

#include <optional>

#include "render/camera.h"

namespace pointrast::view {

// How long the camera must stay still before the full frame follows the motion frames.
constexpr double kRestSeconds = 0.2;

enum class FrameQuality { Motion, Full };

// Whether two cameras give the same image of the same scene.
bool sameCamera(const Camera& a, const Camera& b);

class MotionQuality {
public:
  // An input that moved the camera (a drag's pointer move, a wheel step) arrived at `time`.
  void input(double time);
  // The quality of the frame about to be rendered at `now` with `camera`: Motion when the camera differs
  // from the last frame's and either the previous change was less than kRestSeconds ago, or the latest
  // input followed the one before within kRestSeconds and is itself less than kRestSeconds old; with the
  // camera of the last frame (new content, other settings), Motion only while such inputs continue.
  FrameQuality next(const Camera& camera, double now) const;
  // Records a rendered frame.
  void rendered(const Camera& camera, FrameQuality quality, double now);
  // Whether the last frame was a motion frame and the camera has rested since: render the full frame.
  bool refineDue(double now) const;
  // When refineDue becomes true, while a full frame is owed; for a front end that sleeps until then.
  std::optional<double> refineAt() const;

private:
  bool changed(const Camera& camera) const;
  std::optional<Camera> last_;
  FrameQuality lastQuality_ = FrameQuality::Full;
  double lastChange_ = -1e300;
  double lastInput_ = -1e300;
  bool inputsContinue_ = false; // the last input came within kRestSeconds of the one before
};

} // namespace pointrast::view
