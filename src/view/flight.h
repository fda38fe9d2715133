// A scripted flight over an octree for the desktop viewer (`pointrast view --flight SECONDS`): the inputs
// the browser viewer's load client sends with `serve_load --flight`, played into the session on the
// viewer's clock, and what a user feels measured from them:
//
//   approach  from the first converged frame, six wheel steps of 2 towards (0.5, 0.6) of the viewport,
//             each sent once a frame showed the previous one converged (serve_load waits for a frame;
//             waiting for the view to converge makes the depth each step zooms towards that of the
//             ground, however fast nodes stream): the camera comes down low over the cloud;
//   settle    0.5 s;
//   strokes   for SECONDS, an input every 1/rate s: horizontal pan drags (right button) across 0.8 of
//             the viewport's width in 1.5 s each (flightStroke), swaying by 0.05 vertically, carry the
//             camera sideways at its height over new ground: two strokes one way, then four the other
//             way and four back, so that it sweeps across the cloud and stays over it; frames/s, input
//             to frame (the time an input fell due to the frame that showed it handed to the display)
//             and the points each frame drew (a flight whose frames draw nothing measures nothing);
//   jumps     after 0.3 s each: a standard view (a key) or a zoom of 12-14 steps towards another place,
//             then the frames until one says the level-of-detail view converged (every selected node
//             resident and drawn), 30 s at most.
//
// An input falls due at its scheduled time whether or not the loop is busy, so a slow frame makes the
// inputs behind it wait, as they would in the window system's queue. Times in seconds on any clock; no
// GPU, no window: the viewer applies the inputs and reports the frames it showed.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "render/lod/lod_stats.h"
#include "view/session.h"

namespace pointrast::view {

struct FlightInput {
  enum class Kind { Down, Move, Up, Wheel, Key };
  Kind kind = Kind::Move;
  glm::dvec2 at{0.5, 0.5}; // relative to the viewport: 0..1, x right, y down
  MouseButton button = MouseButton::Right;
  double steps = 0;       // Wheel
  Key key = Key::ViewTop; // Key: pressed and released
};

struct FlightOptions {
  double seconds = 10; // of the strokes
  double rate = 120;   // inputs a second during the strokes: the display's refresh rate
};

// The bounds `view --flight` and `--flight-rate` take.
constexpr double kMaxFlightSeconds = 3600;
constexpr double kMaxFlightRate = 1000;
// Seconds a jump may take to converge before it counts as not converged, as serve_load's bound.
constexpr double kJumpTimeoutSeconds = 30;

class SceneView;

// Where the pointer of a flight's pan stroke is, stroke `index` (from 0) at `u` (0 at its start, 1 at its
// end) of its time, relative to the viewport. A horizontal drag moves the camera along its right vector,
// which stays level, so the strokes keep the height the approach came down to; the directions sweep the
// camera across the cloud and back (+,+,-,-,-,-,+,+,+,+,...). serve_load sends the same strokes.
inline glm::dvec2 flightStroke(uint64_t index, double u) {
  const double direction = ((index + 2) / 4) % 2 == 0 ? 1.0 : -1.0;
  return {0.5 + direction * (0.4 - 0.8 * u), 0.6 + 0.05 * std::sin(u * 3.14159265358979323846)};
}

// Applies one input to the session as the desktop window's events would (a wheel through zoomAtCursor,
// which reads the depth under the cursor from the view).
void applyFlightInput(Session& session, SceneView& view, const FlightInput& input);

class Flight {
public:
  // Throws InputError for seconds outside (0, kMaxFlightSeconds] or a rate outside (0, kMaxFlightRate].
  explicit Flight(const FlightOptions& options);

  // The inputs due at `now`, in order: the viewer applies them all before it renders the next frame.
  std::vector<FlightInput> take(double now);
  // A rendered frame was handed to the display at `now`; `converged`: its level-of-detail view converged
  // (a frame of a cloud drawn whole is always complete: true).
  void frameShown(double now, bool converged);
  // The same for a frame drawn with level of detail: whether it converged, and the node cache's totals,
  // from which the flight reports the nodes streamed while the strokes flew and over the whole session.
  void frameShown(double now, const lod::LodStats& lod);
  // Seconds from `now` until the flight needs the loop again without a frame (an input due, a bound).
  double wait(double now) const;
  bool done() const { return phase_ == Phase::Done; }

  // The figures: "strokes" (frames/s, frames converged, input to frame: inputs, p50, p95, max in ms),
  // "jumps" (each one's frames and ms to converge), whether all converged, the most frames one took, and
  // whether the flight ran to its end ("complete": not when the window was closed first); with level of
  // detail, "streaming": the node cache's budget and the nodes loaded and evicted and the bytes streamed
  // during the strokes and over the whole session, and the strokes' points drawn a frame (median, min,
  // max: a camera flown off the cloud or under its ground draws none).
  nlohmann::json result() const;
  // Why the strokes measured nothing: the median frame drawn with level of detail while they flew drew no
  // point (the camera left the cloud or went under its ground). Empty when they drew, or for a cloud.
  std::string emptyStrokes() const;
  // One line of the same figures.
  std::string summary() const;

private:
  enum class Phase { Start, Approach, Settle, Strokes, Pause, Jump, Done };
  struct Jumped {
    std::string name;
    bool converged = false;
    uint64_t frames = 0;
    double ms = 0;
  };
  struct Streamed {
    uint64_t nodesLoaded = 0, nodesEvicted = 0, bytesStreamed = 0;
  };
  void strokeInputs(double at, std::vector<FlightInput>& out);
  void endStrokes(double now, std::vector<FlightInput>& out);
  void finishJump(bool converged, double now);

  FlightOptions options_;
  Phase phase_ = Phase::Start;
  double until_ = 0;                // Settle, Pause: when the phase ends
  std::optional<double> startSeen_; // Start: when the viewer first asked
  // Approach
  int approachSent_ = 0;
  std::optional<double> approachShownBy_; // the last wheel's send time, until a frame showed it
  // Strokes
  double start_ = 0, end_ = 0;
  uint64_t inputIndex_ = 0; // inputs fall due at start_ + index / rate
  bool down_ = false;
  double strokeStart_ = 0;
  uint64_t strokes_ = 0;          // strokes finished
  std::vector<double> pending_;   // due times of inputs applied and not yet shown
  std::vector<double> latencies_; // ms
  uint64_t framesFlown_ = 0, framesConverged_ = 0;
  // Jumps
  size_t jump_ = 0;
  double jumpSent_ = 0;
  uint64_t jumpFrames_ = 0;
  std::vector<Jumped> jumped_;
  // Level of detail: the totals of the last frame, and when the strokes began and ended
  std::optional<Streamed> streamed_;
  std::optional<uint64_t> pointsDrawn_; // of the frame being reported
  std::vector<double> strokesPointsDrawn_;
  Streamed strokesFrom_, strokesTo_;
  uint64_t cacheBytes_ = 0;
};

} // namespace pointrast::view
