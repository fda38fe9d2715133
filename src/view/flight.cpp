#include "view/flight.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "base/error.h"
#include "report/run_json.h"
#include "view/scene_view.h"

namespace pointrast::view {

namespace {

constexpr int kApproachWheels = 6;
constexpr double kApproachSteps = 2;
constexpr glm::dvec2 kApproachAt{0.5, 0.6};
constexpr double kSettleSeconds = 0.5;
constexpr double kStrokeSeconds = 1.5;
constexpr double kPauseSeconds = 0.3; // before each jump
// While the flight waits on a frame (the approach, a jump) the loop comes back this often to check its
// bounds.
constexpr double kPollSeconds = 0.05;

struct JumpInput {
  const char* name;
  FlightInput input;
};

FlightInput keyInput(Key key) {
  FlightInput in;
  in.kind = FlightInput::Kind::Key;
  in.key = key;
  return in;
}

FlightInput wheelInput(glm::dvec2 at, double steps) {
  FlightInput in;
  in.kind = FlightInput::Kind::Wheel;
  in.at = at;
  in.steps = steps;
  return in;
}

FlightInput pointerInput(FlightInput::Kind kind, glm::dvec2 at) {
  FlightInput in;
  in.kind = kind;
  in.at = at;
  in.button = MouseButton::Right;
  return in;
}

// A standard view, then a zoom towards another place, four times: serve_load's jumps.
const std::vector<JumpInput>& jumpList() {
  static const std::vector<JumpInput> list = {
      {"top view", keyInput(Key::ViewTop)},     {"zoom at 0.3,0.3", wheelInput({0.3, 0.3}, 12)},
      {"front view", keyInput(Key::ViewFront)}, {"zoom at 0.7,0.6", wheelInput({0.7, 0.6}, 12)},
      {"left view", keyInput(Key::ViewLeft)},   {"zoom at 0.5,0.7", wheelInput({0.5, 0.7}, 14)},
      {"overview", keyInput(Key::ViewIso)},     {"zoom at 0.6,0.4", wheelInput({0.6, 0.4}, 14)},
  };
  return list;
}

nlohmann::json msSummary(const std::vector<double>& ms) {
  return {{"inputs", ms.size()},
          {"p50", report::percentile(ms, 0.5)},
          {"p95", report::percentile(ms, 0.95)},
          {"max", report::percentile(ms, 1.0)}};
}

} // namespace

void applyFlightInput(Session& session, SceneView& view, const FlightInput& input) {
  const Viewport v = session.viewport();
  const glm::dvec2 at{input.at.x * v.width, input.at.y * v.height};
  switch (input.kind) {
  case FlightInput::Kind::Down:
    session.mouseDown(input.button, at);
    break;
  case FlightInput::Kind::Move:
    session.mouseMove(at);
    break;
  case FlightInput::Kind::Up:
    session.mouseUp(input.button, at);
    break;
  case FlightInput::Kind::Wheel:
    zoomAtCursor(session, view, at, input.steps);
    break;
  case FlightInput::Kind::Key:
    session.keyDown(input.key);
    session.keyUp(input.key);
    break;
  }
}

Flight::Flight(const FlightOptions& options) : options_(options) {
  if (!(options.seconds > 0 && options.seconds <= kMaxFlightSeconds))
    throw InputError("--flight takes seconds from 0 to " + std::to_string(int(kMaxFlightSeconds)));
  if (!(options.rate > 0 && options.rate <= kMaxFlightRate))
    throw InputError("--flight-rate takes inputs a second from 0 to " + std::to_string(int(kMaxFlightRate)));
}

void Flight::strokeInputs(double at, std::vector<FlightInput>& out) {
  if (!down_) {
    out.push_back(pointerInput(FlightInput::Kind::Down, flightStroke(strokes_, 0.0)));
    pending_.push_back(at);
    down_ = true;
    strokeStart_ = at;
  }
  const double u = std::min(1.0, (at - strokeStart_) / kStrokeSeconds);
  out.push_back(pointerInput(FlightInput::Kind::Move, flightStroke(strokes_, u)));
  pending_.push_back(at);
  if (u >= 1.0) {
    out.push_back(pointerInput(FlightInput::Kind::Up, flightStroke(strokes_, 1.0)));
    pending_.push_back(at);
    down_ = false;
    ++strokes_;
  }
}

void Flight::endStrokes(double now, std::vector<FlightInput>& out) {
  if (down_) out.push_back(pointerInput(FlightInput::Kind::Up, flightStroke(strokes_, 1.0)));
  down_ = false;
  end_ = now;
  if (streamed_) strokesTo_ = *streamed_;
  pending_.clear(); // as serve_load: the figures are those of the frames shown while flying
  phase_ = Phase::Pause;
  until_ = now + kPauseSeconds;
}

void Flight::finishJump(bool converged, double now) {
  Jumped j;
  j.name = jumpList()[jump_].name;
  j.converged = converged;
  j.frames = jumpFrames_;
  j.ms = (now - jumpSent_) * 1e3;
  jumped_.push_back(j);
  ++jump_;
  if (jump_ == jumpList().size()) {
    phase_ = Phase::Done;
    return;
  }
  phase_ = Phase::Pause;
  until_ = now + kPauseSeconds;
}

std::vector<FlightInput> Flight::take(double now) {
  std::vector<FlightInput> out;
  switch (phase_) {
  case Phase::Start:
    // The flight starts from the first converged view, or from whatever is drawn after the bound.
    if (!startSeen_) startSeen_ = now;
    if (now - *startSeen_ > kJumpTimeoutSeconds) phase_ = Phase::Approach;
    break;
  case Phase::Done:
    break;
  case Phase::Approach:
    // A wheel step not shown within the bound is given up on: the approach goes on.
    if (approachShownBy_ && now - *approachShownBy_ > kJumpTimeoutSeconds) approachShownBy_.reset();
    if (approachShownBy_) break;
    if (approachSent_ == kApproachWheels) {
      phase_ = Phase::Settle;
      until_ = now + kSettleSeconds;
      break;
    }
    out.push_back(wheelInput(kApproachAt, kApproachSteps));
    ++approachSent_;
    approachShownBy_ = now;
    break;
  case Phase::Settle:
    if (now < until_) break;
    phase_ = Phase::Strokes;
    start_ = now;
    inputIndex_ = 0;
    framesFlown_ = framesConverged_ = 0;
    latencies_.clear();
    pending_.clear();
    strokesPointsDrawn_.clear();
    if (streamed_) strokesFrom_ = *streamed_;
    [[fallthrough]];
  case Phase::Strokes:
    for (;;) {
      const double at = start_ + double(inputIndex_) / options_.rate;
      if (at > now || at - start_ >= options_.seconds) break;
      strokeInputs(at, out);
      ++inputIndex_;
    }
    if (now - start_ >= options_.seconds) endStrokes(now, out);
    break;
  case Phase::Pause:
    if (now < until_) break;
    out.push_back(jumpList()[jump_].input);
    phase_ = Phase::Jump;
    jumpSent_ = now;
    jumpFrames_ = 0;
    break;
  case Phase::Jump:
    if (now - jumpSent_ > kJumpTimeoutSeconds) finishJump(false, now);
    break;
  }
  return out;
}

void Flight::frameShown(double now, bool converged) {
  switch (phase_) {
  case Phase::Start:
    if (converged) phase_ = Phase::Approach; // the cloud is there to fly over
    break;
  case Phase::Approach:
    // The next wheel step zooms towards the depth under the cursor: it waits until every node of the
    // view is drawn, so that the camera comes down over the ground wherever the streaming stood.
    if (converged) approachShownBy_.reset();
    break;
  case Phase::Strokes:
    ++framesFlown_;
    framesConverged_ += converged;
    if (pointsDrawn_) strokesPointsDrawn_.push_back(double(*pointsDrawn_));
    for (double due : pending_)
      latencies_.push_back((now - due) * 1e3);
    pending_.clear();
    break;
  case Phase::Jump:
    ++jumpFrames_;
    if (converged) finishJump(true, now);
    break;
  default:
    break;
  }
}

void Flight::frameShown(double now, const lod::LodStats& lod) {
  streamed_ = Streamed{lod.nodesLoaded, lod.nodesEvicted, lod.bytesStreamed};
  cacheBytes_ = lod.cacheBytes;
  pointsDrawn_ = lod.pointsDrawn;
  frameShown(now, lod.converged);
  pointsDrawn_.reset();
}

double Flight::wait(double now) const {
  switch (phase_) {
  case Phase::Settle:
  case Phase::Pause:
    return std::max(0.0, until_ - now);
  case Phase::Strokes:
    return std::clamp(start_ + double(inputIndex_) / options_.rate - now, 0.0, kPollSeconds);
  case Phase::Done:
    return std::numeric_limits<double>::infinity();
  default:
    return approachShownBy_ || phase_ != Phase::Approach ? kPollSeconds : 0.0;
  }
}

nlohmann::json Flight::result() const {
  const double seconds = end_ > start_ ? end_ - start_ : 0.0;
  nlohmann::json strokes = {{"seconds", seconds},
                            {"input_rate_hz", options_.rate},
                            {"frames", framesFlown_},
                            {"frames_per_second", seconds > 0 ? double(framesFlown_) / seconds : 0.0},
                            {"frames_converged", framesConverged_},
                            {"input_to_frame_ms", msSummary(latencies_)}};
  nlohmann::json jumps = nlohmann::json::array();
  bool all = jumped_.size() == jumpList().size();
  uint64_t worst = 0;
  for (const Jumped& j : jumped_) {
    nlohmann::json r = {{"jump", j.name}, {"converged", j.converged}, {"frames_to_converge", j.frames}};
    if (j.converged) r["ms_to_converge"] = j.ms;
    jumps.push_back(r);
    all = all && j.converged;
    worst = std::max(worst, j.frames);
  }
  nlohmann::json result = {
      {"what", "serve_load --flight's inputs played into the viewer's session: six wheel steps down low, "
               "pan strokes across the cloud, then jumps, each followed until a frame converged; input "
               "to frame from the time an input fell due to its frame handed to the display"},
      {"strokes", strokes},
      {"jumps", jumps},
      {"jumps_all_converged", all},
      {"jump_frames_to_converge_max", worst},
      {"complete", done()}};
  if (streamed_) {
    auto json = [](const Streamed& s) {
      return nlohmann::json{{"nodes_loaded", s.nodesLoaded},
                            {"nodes_evicted", s.nodesEvicted},
                            {"bytes_streamed", s.bytesStreamed}};
    };
    // Totals count from the node cache's making; none is made again during a flight, and strokes cut short
    // count nothing.
    auto since = [](uint64_t to, uint64_t from) { return to >= from ? to - from : 0; };
    const Streamed flown{since(strokesTo_.nodesLoaded, strokesFrom_.nodesLoaded),
                         since(strokesTo_.nodesEvicted, strokesFrom_.nodesEvicted),
                         since(strokesTo_.bytesStreamed, strokesFrom_.bytesStreamed)};
    const std::vector<double>& p = strokesPointsDrawn_;
    result["strokes"]["points_drawn"] = {{"median", report::percentile(p, 0.5)},
                                         {"min", report::percentile(p, 0.0)},
                                         {"max", report::percentile(p, 1.0)}};
    result["streaming"] = {
        {"cache_bytes", cacheBytes_}, {"strokes", json(flown)}, {"session", json(*streamed_)}};
  }
  return result;
}

std::string Flight::emptyStrokes() const {
  if (strokesPointsDrawn_.empty() || report::percentile(strokesPointsDrawn_, 0.5) > 0) return {};
  return "the flight's strokes drew no points in their median frame: the camera left the cloud or went "
         "under its ground, so the figures time empty frames";
}

std::string Flight::summary() const {
  const nlohmann::json r = result();
  const nlohmann::json& f = r["strokes"];
  char line[256];
  std::snprintf(
      line, sizeof line,
      "flight: %.1f frames/s, input to frame p50 %.1f ms p95 %.1f ms; jumps: %s, at most %llu frames "
      "to converge",
      f["frames_per_second"].get<double>(), f["input_to_frame_ms"]["p50"].get<double>(),
      f["input_to_frame_ms"]["p95"].get<double>(),
      r["jumps_all_converged"].get<bool>() ? "all converged" : "NOT all converged",
      static_cast<unsigned long long>(r["jump_frames_to_converge_max"].get<uint64_t>()));
  return line;
}

} // namespace pointrast::view
