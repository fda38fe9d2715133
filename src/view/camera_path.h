// Camera paths: keyframes recorded in a viewer (K), saved and loaded as JSON, sampled at a frame rate for
// `render --path`. Between keyframes, eye and target follow cubic Hermite curves whose tangents are the
// finite differences of the neighbouring keyframes over their times (a Catmull-Rom spline for uneven
// times), the field of view and up are interpolated linearly. At a keyframe's time the path is exactly
// that keyframe, so the first frame of a path render equals `render` with the first keyframe's camera.
//
// File format (one object):
//   {"format": "pointrast-camera-path", "version": 1,
//    "keyframes": [{"time": 0, "eye": [x, y, z], "target": [x, y, z], "up": [0, 0, 1], "fov": 60}, ...]}
// Times in seconds, strictly increasing; coordinates in the input's own units, like --eye/--target.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "render/camera.h"

namespace pointrast::view {

struct Keyframe {
  double time = 0; // seconds from the path's start
  Camera camera;
};

// A loaded path holds at most this many keyframes (a day of keyframes at one a second).
constexpr size_t kMaxKeyframes = 86'400;
// Path files larger than this are refused before parsing.
constexpr uint64_t kMaxPathFileBytes = 16ull << 20;
// Seconds between keyframes recorded with K, unless the viewer's panel says otherwise.
constexpr double kDefaultKeyframeSeconds = 2.0;

class CameraPath {
public:
  const std::vector<Keyframe>& keyframes() const { return keyframes_; }
  bool empty() const { return keyframes_.empty(); }
  void clear() { keyframes_.clear(); }
  // Appends a keyframe `seconds` after the last one (at time 0 when the path is empty).
  void append(const Camera& camera, double seconds = kDefaultKeyframeSeconds);
  // Seconds from the first keyframe to the last.
  double duration() const;
  // The camera at `time` seconds from the start, clamped to [0, duration()]. Needs a keyframe.
  Camera sample(double time) const;
  // Frames of a render at `fps`: one at every 1/fps seconds from the first keyframe up to and including
  // the last (a single keyframe gives one frame).
  uint64_t frameCount(double fps) const;

  // Throws InputError naming the file: unreadable, too large, not JSON, wrong format or version, no
  // keyframes, a non-finite number, times not strictly increasing, or a keyframe validateCamera refuses.
  static CameraPath load(const std::filesystem::path& path);
  static CameraPath parse(const std::string& text, const std::string& name);
  std::string toJson() const;
  // Writes "<path>.partial" and renames it, like every writer.
  void save(const std::filesystem::path& path) const;

private:
  std::vector<Keyframe> keyframes_;
};

// The name `render --path` takes for a turntable instead of a file.
constexpr const char* kOrbitPathName = "orbit";
// A turntable: the camera turned once around its target about `up` in `seconds`, as keyframes every
// 1/64 turn (the spline through them stays within 0.1 % of the circle's radius).
CameraPath orbitPath(const Camera& start, double seconds = 5.0);

} // namespace pointrast::view
