// The scripted flight (`view --flight`) on a made-up clock: its phases, the inputs it plays, and the
// figures it reports from the frames a viewer says it showed. No GPU or window needed.
#include <algorithm>

#include <gtest/gtest.h>

#include "base/error.h"
#include "view/flight.h"

namespace {

using namespace pointrast;
using view::Flight;
using view::FlightInput;

// Drives a flight as a viewer loop that renders all the time does: take the inputs due, then show a frame.
struct Loop {
  Flight& flight;
  double now = 0;
  std::vector<FlightInput> inputs;
  // One iteration at `now`: inputs taken, then a frame shown `frameSeconds` later.
  void step(double frameSeconds, bool converged) {
    std::vector<FlightInput> due = flight.take(now);
    inputs.insert(inputs.end(), due.begin(), due.end());
    now += frameSeconds;
    flight.frameShown(now, converged);
  }
};

// Plays the approach, the strokes and the pause with a converged frame every 10 ms, up to the first jump's
// input (taken, its frame not yet shown).
void untilFirstJump(Loop& loop) {
  for (int i = 0; i < 100000; ++i) {
    std::vector<FlightInput> due = loop.flight.take(loop.now);
    loop.inputs.insert(loop.inputs.end(), due.begin(), due.end());
    if (!due.empty() && due.back().kind == FlightInput::Kind::Key) return;
    loop.flight.frameShown(loop.now += 0.01, true);
  }
}

TEST(Flight, RefusesSecondsAndRatesOutOfRange) {
  EXPECT_THROW(Flight({0, 120}), InputError);
  EXPECT_THROW(Flight({-1, 120}), InputError);
  EXPECT_THROW(Flight({view::kMaxFlightSeconds * 2, 120}), InputError);
  EXPECT_THROW(Flight({1, 0}), InputError);
  EXPECT_THROW(Flight({1, view::kMaxFlightRate + 1}), InputError);
  EXPECT_NO_THROW(Flight({1, 120}));
}

TEST(Flight, WaitsForTheFirstConvergedFrameThenApproachesOneWheelPerConvergedFrame) {
  Flight flight({2, 100});
  EXPECT_TRUE(flight.take(0).empty()) << "nothing before the first frame";
  flight.frameShown(0.1, false);
  EXPECT_TRUE(flight.take(0.15).empty()) << "nothing before the view converged";
  flight.frameShown(0.2, true);
  std::vector<FlightInput> first = flight.take(0.25);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].kind, FlightInput::Kind::Wheel);
  EXPECT_DOUBLE_EQ(first[0].steps, 2);
  EXPECT_TRUE(flight.take(0.3).empty()) << "the next wheel waits for the frame that shows this one";
  flight.frameShown(0.4, false);
  EXPECT_TRUE(flight.take(0.45).empty()) << "... converged";
  flight.frameShown(0.5, true);
  EXPECT_EQ(flight.take(0.55).size(), 1u);
}

TEST(Flight, AViewThatNeverConvergesStartsTheApproachAfterTheBound) {
  Flight flight({2, 100});
  flight.frameShown(0.1, false);
  EXPECT_TRUE(flight.take(0.2).empty());
  EXPECT_TRUE(flight.take(0.2 + view::kJumpTimeoutSeconds + 0.1).empty()) << "the bound passed: approach";
  EXPECT_EQ(flight.take(0.2 + view::kJumpTimeoutSeconds + 0.2).size(), 1u);
}

TEST(Flight, StrokesPlayInputsAtTheRateAndMeasureInputToFrame) {
  Flight flight({1, 100});
  Loop loop{flight};
  // Frames of 50 ms while flying: 5 inputs wait behind each frame, so input to frame spans 50 to 100 ms.
  for (int i = 0; i < 100000 && !flight.done(); ++i)
    loop.step(0.05, true);
  ASSERT_TRUE(flight.done());
  const nlohmann::json r = flight.result();
  EXPECT_TRUE(r["complete"].get<bool>());
  const nlohmann::json& s = r["strokes"];
  EXPECT_NEAR(s["seconds"].get<double>(), 1.0, 0.06);
  EXPECT_NEAR(s["frames_per_second"].get<double>(), 20.0, 1.5);
  EXPECT_EQ(s["frames"], s["frames_converged"]);
  const nlohmann::json& ms = s["input_to_frame_ms"];
  // 100 moves in a second, plus the presses and releases of the strokes (one stroke is 1.5 s: one press).
  EXPECT_GE(ms["inputs"].get<size_t>(), 90u);
  EXPECT_LE(ms["inputs"].get<size_t>(), 102u);
  EXPECT_GE(ms["p50"].get<double>(), 50.0 - 1e-6);
  EXPECT_LE(ms["max"].get<double>(), 100.0 + 1e-6);
  EXPECT_GT(ms["p95"].get<double>(), ms["p50"].get<double>());
  // Horizontal pan drags with the right button: the first from the right towards the left of the viewport,
  // at the height of the approach's wheel steps, swaying by at most 0.05.
  size_t downs = 0, moves = 0;
  double lowestX = 1;
  for (const FlightInput& in : loop.inputs) {
    if (in.kind == FlightInput::Kind::Down) {
      ++downs;
      EXPECT_EQ(in.button, view::MouseButton::Right);
      EXPECT_DOUBLE_EQ(in.at.x, 0.9);
    }
    if (in.kind == FlightInput::Kind::Move) {
      ++moves;
      lowestX = std::min(lowestX, in.at.x);
      EXPECT_GE(in.at.y, 0.6 - 1e-9);
      EXPECT_LE(in.at.y, 0.65 + 1e-9);
    }
  }
  EXPECT_EQ(downs, 1u);
  EXPECT_GE(moves, 99u);
  EXPECT_LT(lowestX, 0.9 - 0.8 / 1.5 * 0.9) << "a second carries the stroke two thirds of its way";
}

TEST(Flight, StrokesKeepTheHeightAndSweepAcrossAndBack) {
  // Each stroke ends at the height it started (a level camera move) and spans 0.8 of the width.
  double position = 0; // where the camera is, in strokes to the right of where it started
  double lowest = 0, highest = 0;
  for (uint64_t i = 0; i < 40; ++i) {
    const glm::dvec2 a = view::flightStroke(i, 0.0), b = view::flightStroke(i, 1.0);
    EXPECT_DOUBLE_EQ(a.y, b.y);
    EXPECT_NEAR(std::abs(a.x - b.x), 0.8, 1e-12);
    EXPECT_GT(view::flightStroke(i, 0.5).y, a.y) << "sways while it drags";
    position += a.x > b.x ? 1 : -1; // dragging the view left moves the camera right
    lowest = std::min(lowest, position);
    highest = std::max(highest, position);
  }
  // Two strokes one way, then four the other way and four back: it stays within two strokes of the start.
  EXPECT_EQ(highest, 2);
  EXPECT_EQ(lowest, -2);
  EXPECT_EQ(position, 0);
}

TEST(Flight, StrokesWhoseFramesDrawNoPointsAreSaid) {
  for (uint64_t drawn : {uint64_t(0), uint64_t(1000)}) {
    Flight flight({0.5, 100});
    lod::LodStats lod;
    lod.converged = true;
    lod.pointsDrawn = drawn;
    double now = 0;
    for (int i = 0; i < 100000 && !flight.done(); ++i) {
      flight.take(now);
      flight.frameShown(now += 0.02, lod);
    }
    ASSERT_TRUE(flight.done());
    EXPECT_EQ(flight.emptyStrokes().empty(), drawn > 0) << drawn;
  }
  // A cloud drawn whole reports no points a frame: nothing to say.
  Flight cloud({0.2, 100});
  Loop loop{cloud};
  for (int i = 0; i < 100000 && !cloud.done(); ++i)
    loop.step(0.02, true);
  EXPECT_TRUE(cloud.emptyStrokes().empty());
}

TEST(Flight, EachJumpCountsItsFramesUntilOneConverged) {
  Flight flight({0.1, 100});
  Loop loop{flight};
  untilFirstJump(loop);
  // The first jump (a key): three frames not converged, then one that is.
  ASSERT_EQ(loop.inputs.back().key, view::Key::ViewTop);
  for (int i = 0; i < 3; ++i)
    flight.frameShown(loop.now += 0.02, false);
  flight.frameShown(loop.now += 0.02, true);
  // The rest converge at once.
  for (int i = 0; i < 100000 && !flight.done(); ++i)
    loop.step(0.01, true);
  ASSERT_TRUE(flight.done());
  const nlohmann::json r = flight.result();
  ASSERT_EQ(r["jumps"].size(), 8u);
  EXPECT_EQ(r["jumps"][0]["jump"], "top view");
  EXPECT_EQ(r["jumps"][0]["frames_to_converge"], 4);
  EXPECT_NEAR(r["jumps"][0]["ms_to_converge"].get<double>(), 80, 1e-6);
  EXPECT_EQ(r["jumps"][1]["frames_to_converge"], 1);
  EXPECT_TRUE(r["jumps_all_converged"].get<bool>());
  EXPECT_EQ(r["jump_frames_to_converge_max"], 4);
  size_t keys = 0, zooms = 0;
  for (const FlightInput& in : loop.inputs) {
    keys += in.kind == FlightInput::Kind::Key;
    zooms += in.kind == FlightInput::Kind::Wheel && in.steps >= 12;
  }
  EXPECT_EQ(keys, 4u);
  EXPECT_EQ(zooms, 4u);
}

TEST(Flight, AJumpThatNeverConvergesEndsAtItsBoundAndIsSaid) {
  Flight flight({0.1, 100});
  Loop loop{flight};
  untilFirstJump(loop);
  // Frames that never converge, one a second, past the bound.
  for (int i = 0; i < 31; ++i)
    loop.step(1.0, false);
  for (int i = 0; i < 100000 && !flight.done(); ++i)
    loop.step(0.01, true);
  ASSERT_TRUE(flight.done());
  const nlohmann::json r = flight.result();
  EXPECT_FALSE(r["jumps"][0]["converged"].get<bool>());
  EXPECT_FALSE(r["jumps"][0].contains("ms_to_converge"));
  EXPECT_FALSE(r["jumps_all_converged"].get<bool>());
  EXPECT_NE(flight.summary().find("NOT all converged"), std::string::npos) << flight.summary();
}

TEST(Flight, NodesStreamedDuringTheStrokesAndTheSessionFromTheCachesTotals) {
  Flight flight({1, 100});
  lod::LodStats lod;
  lod.cacheBytes = 1 << 20;
  lod.converged = true;
  double now = 0;
  // Every frame loads 2 nodes (1000 bytes) and evicts 1, from the first frame to the last, and draws 10 more
  // points than the one before.
  auto frame = [&] {
    flight.take(now);
    lod.pointsDrawn += 10;
    lod.nodesLoaded += 2;
    lod.nodesEvicted += 1;
    lod.bytesStreamed += 1000;
    flight.frameShown(now += 0.05, lod);
  };
  uint64_t strokesFrames = 0;
  for (int i = 0; i < 100000 && !flight.done(); ++i) {
    frame();
    strokesFrames = flight.result()["strokes"]["frames"].get<uint64_t>();
  }
  ASSERT_TRUE(flight.done());
  const nlohmann::json r = flight.result();
  ASSERT_TRUE(r.contains("streaming")) << r.dump();
  const nlohmann::json& s = r["streaming"];
  EXPECT_EQ(s["cache_bytes"], 1 << 20);
  EXPECT_EQ(s["session"]["nodes_loaded"], lod.nodesLoaded);
  EXPECT_EQ(s["session"]["nodes_evicted"], lod.nodesEvicted);
  EXPECT_EQ(s["session"]["bytes_streamed"], lod.bytesStreamed);
  // The strokes' share: the frames shown while they flew (the frame that ends them loads after the end).
  ASSERT_GT(strokesFrames, 10u);
  EXPECT_NEAR(s["strokes"]["nodes_evicted"].get<double>(), double(strokesFrames), 1.0);
  EXPECT_NEAR(s["strokes"]["nodes_loaded"].get<double>(), 2.0 * strokesFrames, 2.0);
  EXPECT_NEAR(s["strokes"]["bytes_streamed"].get<double>(), 1000.0 * strokesFrames, 1000.0);
  const nlohmann::json& drawn = r["strokes"]["points_drawn"];
  EXPECT_LT(drawn["min"].get<double>(), drawn["median"].get<double>());
  EXPECT_LT(drawn["median"].get<double>(), drawn["max"].get<double>());
  EXPECT_NEAR(drawn["max"].get<double>() - drawn["min"].get<double>(), 10.0 * (strokesFrames - 1), 10.0);
  EXPECT_FALSE(Flight({1, 100}).result().contains("streaming")) << "no level of detail, no streaming figures";
}

TEST(Flight, AFlightCutShortIsNotComplete) {
  Flight flight({5, 100});
  flight.frameShown(0, true);
  flight.take(0.1);
  const nlohmann::json r = flight.result();
  EXPECT_FALSE(r["complete"].get<bool>());
  EXPECT_FALSE(r["jumps_all_converged"].get<bool>());
  EXPECT_EQ(r["strokes"]["frames"], 0);
}

} // namespace
