// `pointrast view --flight` on lavapipe (validation layer on): the viewer flies serve_load's flight over a
// generated octree whose node cache holds an eighth of it, closes by itself, and its --stats JSON has the
// flight's figures with sane values (those --events reports agree).
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "viewer_harness.h"

namespace pointrast::test {
namespace {

std::filesystem::path flightTempDir() {
  static std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("pointrast_window_flight_" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

TEST(ViewerFlight, FliesOverAStreamedOctreeAndReportsFramesLatencyAndJumps) {
  Xvfb xvfb;
  ASSERT_FALSE(xvfb.display().empty()) << "Xvfb did not start (scripts/install-deps.sh installs xvfb)";
  const std::filesystem::path dir = flightTempDir();
  const std::string bin = "'" + pointrastBinary() + "'";
  const std::filesystem::path las = dir / "terrain.las", octree = dir / "octree";
  std::filesystem::remove_all(octree);
  ASSERT_EQ(std::system((bin + " generate terrain --points 200k -o '" + las.string() + "' -q").c_str()), 0);
  ASSERT_EQ(std::system((bin + " lod '" + las.string() + "' -o '" + octree.string() + "' -q").c_str()), 0);
  uint64_t bytes = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(octree))
    if (entry.is_regular_file()) bytes += entry.file_size();

  const std::filesystem::path stats = dir / "flight.json", events = dir / "events.jsonl",
                              log = dir / "log.txt";
  const double seconds = 2, rate = 120;
  const std::string command = "DISPLAY=" + xvfb.display() +
                              " XDG_RUNTIME_DIR=/tmp POINTRAST_VALIDATION=1 timeout 300 " + bin + " view '" +
                              octree.string() + "' --gpu-memory " + std::to_string(bytes / 8) +
                              " --width 320 --height 240 --no-panel --no-vsync --flight 2 --flight-rate 120" +
                              " --stats '" + stats.string() + "' --path '" + (dir / "path.json").string() +
                              "' --events -q >'" + events.string() + "' 2>'" + log.string() + "'";
  const int status = std::system(command.c_str());
  std::ifstream logFile(log);
  const std::string errors((std::istreambuf_iterator<char>(logFile)), std::istreambuf_iterator<char>());
  ASSERT_EQ(status, 0) << "the viewer closes by itself once the flight is done: " << errors;
  EXPECT_NE(errors.find("flight: "), std::string::npos) << "one line of the figures: " << errors;

  std::ifstream statsFile(stats);
  const nlohmann::json j = nlohmann::json::parse(statsFile, nullptr, false);
  ASSERT_TRUE(j.is_object() && j.contains("flight")) << j.dump();
  const nlohmann::json& f = j["flight"];
  EXPECT_TRUE(f["complete"].get<bool>());
  const nlohmann::json& s = f["strokes"];
  EXPECT_NEAR(s["seconds"].get<double>(), seconds, 0.5);
  EXPECT_EQ(s["input_rate_hz"].get<double>(), rate);
  EXPECT_GT(s["frames"].get<uint64_t>(), 0u);
  EXPECT_LE(s["frames_converged"].get<uint64_t>(), s["frames"].get<uint64_t>());
  const double fps = s["frames_per_second"].get<double>();
  EXPECT_GT(fps, 0.5);
  EXPECT_LE(fps, rate * 1.1) << "a frame is rendered when an input changed the view or a node arrived";
  const nlohmann::json& ms = s["input_to_frame_ms"];
  // Every move of the strokes is shown by some frame (the last few may still be in flight at the end).
  EXPECT_GE(ms["inputs"].get<double>(), seconds * rate * 0.5);
  EXPECT_GT(ms["p50"].get<double>(), 0);
  EXPECT_GE(ms["p95"].get<double>(), ms["p50"].get<double>());
  EXPECT_GE(ms["max"].get<double>(), ms["p95"].get<double>());
  EXPECT_LT(ms["max"].get<double>(), 30e3);
  ASSERT_EQ(f["jumps"].size(), 8u);
  for (const nlohmann::json& jump : f["jumps"]) {
    EXPECT_TRUE(jump["converged"].get<bool>()) << jump.dump();
    EXPECT_GE(jump["frames_to_converge"].get<uint64_t>(), 1u) << jump.dump();
    EXPECT_LE(jump["frames_to_converge"].get<uint64_t>(), 30u) << jump.dump();
    EXPECT_GT(jump["ms_to_converge"].get<double>(), 0) << jump.dump();
  }
  EXPECT_TRUE(f["jumps_all_converged"].get<bool>());
  EXPECT_LE(f["jump_frames_to_converge_max"].get<uint64_t>(), 30u);
  // The session's own figures count the flight's frames too, and the octree did stream: nodes were evicted
  // from a cache an eighth of its size.
  EXPECT_GE(j["frames"].get<uint64_t>(), s["frames"].get<uint64_t>());
  std::ifstream eventFile(events);
  uint64_t frames = 0;
  nlohmann::json lastLod;
  bool flightEvent = false;
  int validationErrors = -1;
  for (std::string line; std::getline(eventFile, line);) {
    const nlohmann::json e = nlohmann::json::parse(line, nullptr, false);
    if (!e.is_object()) continue;
    if (e.value("event", "") == "frame") {
      ++frames;
      if (e.contains("lod")) lastLod = e["lod"];
    }
    if (e.value("event", "") == "flight") flightEvent = e["flight"] == f;
    if (e.value("event", "") == "exit") validationErrors = e.value("validation_errors", -1);
  }
  EXPECT_EQ(frames, j["frames"].get<uint64_t>());
  // Nodes streamed through a cache an eighth of the octree; the flight's totals are the last frame's.
  ASSERT_TRUE(f.contains("streaming")) << f.dump();
  const nlohmann::json& streaming = f["streaming"];
  EXPECT_GT(streaming["cache_bytes"].get<uint64_t>(), 0u);
  EXPECT_LE(streaming["cache_bytes"].get<uint64_t>(), bytes / 8);
  EXPECT_GT(streaming["session"]["nodes_loaded"].get<uint64_t>(), 0u);
  EXPECT_GT(streaming["session"]["bytes_streamed"].get<uint64_t>(), 0u);
  ASSERT_TRUE(lastLod.is_object());
  EXPECT_EQ(streaming["session"]["nodes_loaded"], lastLod["nodes_loaded"]);
  EXPECT_EQ(streaming["session"]["nodes_evicted"], lastLod["nodes_evicted"]);
  EXPECT_GE(streaming["session"]["nodes_loaded"].get<uint64_t>(),
            streaming["strokes"]["nodes_loaded"].get<uint64_t>());
  EXPECT_LE(s["points_drawn"]["min"].get<double>(), s["points_drawn"]["median"].get<double>());
  EXPECT_LE(s["points_drawn"]["median"].get<double>(), s["points_drawn"]["max"].get<double>());
  EXPECT_GT(s["points_drawn"]["max"].get<double>(), 0) << "the strokes start over the cloud";
  EXPECT_TRUE(flightEvent) << "--events has the same figures";
  EXPECT_EQ(validationErrors, 0) << errors;
}

TEST(ViewerFlight, BadFlightOptionsAreOneLineBeforeAnyWindow) {
  // They are said before the window opens, so a display that is named but not there never gets reached.
  const std::string bin = "DISPLAY=:nowhere XDG_RUNTIME_DIR=/tmp '" + pointrastBinary() + "'";
  for (const char* args : {"--flight -1", "--flight 1 --flight-rate 0", "--flight-rate 60"}) {
    const std::string out =
        shellOutput(bin + " view terrain --points 1k " + args + " -q 2>&1 >/dev/null; echo \"exit $?\"");
    EXPECT_NE(out.find("--flight"), std::string::npos) << args << ": " << out;
    EXPECT_NE(out.find("exit 1"), std::string::npos) << args << ": " << out;
  }
}

} // namespace
} // namespace pointrast::test
