// The browser viewer on several ranks as a user starts it: `mpirun -np N pointrast serve ...` on lavapipe,
// reached by the load tool's WebSocket client. Rank 0's frames are every rank's shares composited: its
// lossless screenshot must be the one-process server's (bit for bit for atomicmin; for lod, the words of the
// composite may differ from one rank's only at depth ties, as in the render tests).
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <csignal>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include "cli/cli_harness.h"
#include "mpi/mpi_harness.h"
#include "mpi/mpi_job.h"
#include "view/web/protocol.h"
#include "web/image_compare.h"
#include "web/serve_harness.h"
#include "ws_client.h"

namespace fs = std::filesystem;
using pointrast::test::cliTempDir;
using pointrast::test::Json;
using pointrast::test::pointrastBinary;
using pointrast::test::runPointrast;
using pointrast::test::ServeProcess;
using pointrast::test::slurp;

namespace {

using namespace pointrast::test::mpi;

// What a client of the server saw: the screenshot (PNG) of its view once a full frame at rest was shown
// (for an octree: once its level of detail converged), and what the pick tool answered.
struct Seen {
  std::string png;
  Json state, picked;
};

Seen look(uint16_t port, uint32_t w, uint32_t h, bool octree, double seconds = 180) {
  using namespace pointrast::view::web;
  Seen seen;
  pointrast::wsclient::Client ws;
  if (!ws.connect("127.0.0.1", port, "/ws")) return seen;
  ws.sendText(Json{{"t", "resize"}, {"w", w}, {"h", h}}.dump());
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  bool ready = false, asked = false, picking = false;
  while (std::chrono::steady_clock::now() < deadline) {
    auto m = ws.receive(std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count());
    if (!m) break;
    if (m->opcode == 1) {
      const Json j = Json::parse(m->text(), nullptr, false);
      if (!j.is_object()) continue;
      const std::string type = j.value("t", "");
      if (type == "state") {
        seen.state = j;
        ready = !octree || (j.contains("stats") && j["stats"].contains("lod") &&
                            j["stats"]["lod"].value("converged", false));
      }
      if (type == "picked") {
        seen.picked = j;
        if (!seen.png.empty()) break;
      }
      continue;
    }
    if (m->opcode != 2 || m->data.size() < kFrameHeaderBytes) continue;
    const FrameHeader header = readFrameHeader(m->data.data());
    if (header.magic == kScreenshotMagic) {
      seen.png.assign(m->data.begin() + kFrameHeaderBytes, m->data.end());
      if (!seen.picked.is_null()) break;
      continue;
    }
    if (header.magic != kFrameMagic) continue;
    ws.sendText(Json{{"t", "ack"}, {"frame", header.frame}}.dump());
    // A frame's state comes before its image: a full frame drawn at rest shows the view to compare.
    if (ready && (header.flags & kFrameFull) && !asked) {
      asked = true;
      ws.sendText(Json{{"t", "key"}, {"key", "Screenshot"}, {"down", true}}.dump());
      ws.sendText(Json{{"t", "key"}, {"key", "Screenshot"}, {"down", false}}.dump());
    }
    if (asked && !picking) {
      picking = true;
      ws.sendText(Json{{"t", "pickpoint"}, {"x", 0.5}, {"y", 0.5}}.dump());
    }
  }
  return seen;
}

struct Served {
  Seen seen;
  std::vector<uint64_t> words; // the composite's words (under mpirun)
  int exitCode = -1;
  std::string err;
};

// `pointrast serve ARGS` on `ranks` ranks (0: without mpirun), looked at by one client, then stopped.
Served serveOn(uint32_t ranks, const std::string& args, uint32_t w, uint32_t h, bool octree) {
  const fs::path words = cliTempDir() / ("serve_words_" + std::to_string(ranks) + ".bin");
  fs::remove(words);
  Served s;
  ServeProcess server(args, ranks == 0 ? "" : mpirun(ranks, words));
  EXPECT_TRUE(server.listening()) << server.stderrText();
  if (!server.listening()) return s;
  s.seen = look(server.port(), w, h, octree);
  if (ranks == 0) {
    s.exitCode = server.stop();
  } else {
    // Rank 0 stops the job: mpirun, signalled itself, would end every rank with its own status.
    const auto listening =
        server.waitFor([](const Json& j) { return j.value("event", "") == "listening"; }, 1);
    EXPECT_TRUE(listening && listening->contains("pid"));
    if (listening && listening->contains("pid")) kill(pid_t((*listening)["pid"].get<int>()), SIGTERM);
    s.exitCode = server.stop(0); // waits for the job's end
  }
  s.err = server.stderrText();
  s.words = readWords(words);
  return s;
}

const std::string kTerrain = "terrain --points 40000 --eye 500022.37,3999984.26,217.29 "
                             "--target 500022.37,4000018.99,192.97";

// Every rank generates its share of the terrain; the composite of two is the one-process frame exactly,
// and the pick tool, which reads points on the host, says in the page why it does not run.
TEST(MpiServe, TwoRanksServeTheOneProcessFrameExactly) {
  REQUIRE_MPI();
  const std::string args = kTerrain + " --method atomicmin --point-size 2";
  const Served one = serveOn(0, args, 240, 160, false);
  const Served two = serveOn(2, args, 240, 160, false);
  ASSERT_FALSE(one.seen.png.empty()) << one.err;
  ASSERT_FALSE(two.seen.png.empty()) << two.err;
  EXPECT_TRUE(two.seen.png == one.seen.png) << "the 2-rank screenshot differs from one process's";
  EXPECT_EQ(two.exitCode, 0) << two.err;
  EXPECT_EQ(one.exitCode, 0) << one.err;
  // The page's statistics count every rank's points.
  EXPECT_EQ(two.seen.state["stats"]["points"], 40000) << two.seen.state.dump();
  ASSERT_EQ(two.words.size(), 240u * 160u);
  uint64_t covered = 0;
  for (uint64_t w : two.words)
    covered += w != kEmpty;
  EXPECT_GT(covered, two.words.size() / 4) << "the frame must show the scene";
  const std::string point = two.seen.picked["pick"].value("point", std::string());
  EXPECT_NE(point.find("unavailable: under mpirun each rank holds only its share"), std::string::npos)
      << two.seen.picked.dump();
  EXPECT_EQ(one.seen.picked.dump().find("unavailable"), std::string::npos) << one.seen.picked.dump();
  EXPECT_FALSE(one.seen.picked.is_null());
}

// An octree: each rank reads and draws its share of every frame's nodes. The converged frame of two ranks
// equals one rank's up to depth ties, and one rank under mpirun is the one-process server.
TEST(MpiServe, TwoRanksServeAnOctreesConvergedFrame) {
  REQUIRE_MPI();
  const fs::path las = cliTempDir() / "serve_terrain.las", octree = cliTempDir() / "serve_terrain";
  fs::remove_all(octree);
  ASSERT_EQ(runPointrast("generate terrain --points 60000 -o " + las.string() + " -q").exitCode, 0);
  const pointrast::test::CliResult built =
      runPointrast("lod " + las.string() + " -o " + octree.string() + " -q");
  ASSERT_EQ(built.exitCode, 0) << built.err;
  const std::string args = "'" + octree.string() + "' --method lod --min-node-px 0";
  const Served plain = serveOn(0, args, 240, 160, true);
  const Served one = serveOn(1, args, 240, 160, true);
  const Served two = serveOn(2, args, 240, 160, true);
  ASSERT_FALSE(plain.seen.png.empty()) << plain.err;
  ASSERT_FALSE(one.seen.png.empty()) << one.err;
  ASSERT_FALSE(two.seen.png.empty()) << two.err;
  EXPECT_TRUE(one.seen.png == plain.seen.png) << "one rank under mpirun differs from one process";
  ASSERT_EQ(one.words.size(), 240u * 160u);
  ASSERT_EQ(two.words.size(), one.words.size());
  uint64_t covered = 0, differ = 0, ties = 0;
  for (size_t i = 0; i < one.words.size(); ++i) {
    covered += one.words[i] != kEmpty;
    if (one.words[i] == two.words[i]) continue;
    ++differ;
    if (one.words[i] != kEmpty && two.words[i] != kEmpty && one.words[i] >> 32 == two.words[i] >> 32) ++ties;
  }
  EXPECT_GT(covered, one.words.size() / 4);
  EXPECT_EQ(differ, ties) << differ - ties << " pixels differ in depth";
  if (differ == 0) {
    EXPECT_TRUE(two.seen.png == one.seen.png);
  }
  EXPECT_EQ(two.seen.state["stats"]["points"], plain.seen.state["stats"]["points"]) << two.seen.state.dump();
  EXPECT_EQ(two.exitCode, 0) << two.err;
}

int errorLines(const std::string& err) {
  int lines = 0;
  for (size_t at = err.find("pointrast:"); at != std::string::npos; at = err.find("pointrast:", at + 1))
    ++lines;
  return lines;
}

// A rank given a damaged file ends the whole job, rank 0's server included, with one line naming it.
TEST(MpiServe, ARankWithADamagedFileEndsTheServerWithOneLine) {
  REQUIRE_MPI();
  const fs::path good = cliTempDir() / "serve_good.las", bad = cliTempDir() / "serve_damaged.las";
  ASSERT_EQ(runPointrast("generate terrain --points 20000 -o " + good.string() + " -q").exitCode, 0);
  fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
  fs::resize_file(bad, fs::file_size(good) / 2); // the header promises twice the records present
  const std::string tail = " --port 0 -q";
  const MpiRun r = runMpi("-np 1 " + pointrastBinary() + " serve " + good.string() + tail + " : -np 1 " +
                          pointrastBinary() + " serve " + bad.string() + tail);
  EXPECT_FALSE(r.signaled) << r.err;
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_LT(r.seconds, 60);
  EXPECT_EQ(errorLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("pointrast: rank 1: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("serve_damaged.las: header claims"), std::string::npos) << r.err;
}

// Methods whose frames cannot be composited are refused before anything is read, on every rank alike.
TEST(MpiServe, MethodsThatBlendAreRefusedWithOneLine) {
  REQUIRE_MPI();
  const MpiRun r =
      runMpi("-np 2 " + pointrastBinary() + " serve terrain --points 20000 --method hqs --port 0 -q");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(errorLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("pointrast: hqs blends points, so ranks' frames cannot be composited"),
            std::string::npos)
      << r.err;
}

// The page in Debian's chromium (tests/web/browser.mjs) shows a 2-rank server's frame: the canvas holds the
// frame `render` draws of the same camera on one process, within the JPEG tolerance of the browser tests.
TEST(MpiServe, ThePageShowsATwoRankFrame) {
  REQUIRE_MPI();
  const std::string web = std::string(POINTRAST_SOURCE_DIR) + "/tests/web";
  if (!fs::exists(web + "/node_modules/playwright-core"))
    FAIL() << "playwright-core is not installed: run scripts/web-test-setup.sh (npm ci in tests/web)";
  if (!fs::exists("/usr/bin/chromium")) FAIL() << "chromium is missing: run scripts/install-deps.sh";
  const fs::path words = cliTempDir() / "serve_words_browser.bin";
  ServeProcess server(kTerrain + " --method atomicmin --point-size 2", mpirun(2, words));
  ASSERT_TRUE(server.listening()) << server.stderrText();
  const fs::path dir = pointrast::test::scratchDir("mpi_browser_frame");
  const Json r = pointrast::test::browser("frame", server.url(), dir, Json::object());
  ASSERT_TRUE(r.contains("frame")) << r.dump();
  EXPECT_EQ(r["errors"], Json::array());
  EXPECT_EQ(r["frame"]["full"], true);
  EXPECT_EQ(r["frame"]["width"], 640);
  const std::string ref = (dir / "ref.png").string();
  ASSERT_EQ(
      runPointrast("render " + kTerrain + " --point-size 2 --width 640 --height 480 -q -o " + ref).exitCode,
      0);
  const pointrast::test::ImageDifference d = pointrast::test::comparePngs((dir / "canvas.png").string(), ref);
  ASSERT_TRUE(d.sameSize);
  EXPECT_GE(d.psnr, pointrast::test::kJpegPsnr) << "mean abs " << d.meanAbs;
  EXPECT_LE(d.meanAbs, pointrast::test::kJpegMeanAbs);
  const auto listening = server.waitFor([](const Json& j) { return j.value("event", "") == "listening"; }, 1);
  ASSERT_TRUE(listening && listening->contains("pid"));
  kill(pid_t((*listening)["pid"].get<int>()), SIGTERM);
  EXPECT_EQ(server.stop(0), 0) << server.stderrText();
}

// bench on two ranks: each rank times its share; every result carries each rank's time and the composite's
// cost (JSON and the Markdown table), its points are the whole scene's and its time the slowest rank's.
TEST(MpiBench, TwoRanksReportEachRanksTimeAndTheComposite) {
  REQUIRE_MPI();
  const fs::path out = cliTempDir() / "bench_ranks";
  fs::remove_all(out);
  const MpiRun r = runMpi("-np 2 " + pointrastBinary() +
                          " bench terrain --points 40000 --methods atomicmin,batch --orders original "
                          "--views overview --frames 3 --width 240 --height 160 --copy-size 16M --json -q "
                          "--name ranks --out " +
                          out.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  int results = 0;
  while (std::getline(lines, line)) {
    const Json j = Json::parse(line, nullptr, false);
    ASSERT_TRUE(j.is_object()) << line;
    ++results;
    EXPECT_EQ(j["status"], "ok") << line;
    EXPECT_EQ(j["points"], 40000) << line;
    const Json& mpi = j["mpi"];
    ASSERT_TRUE(mpi.is_object()) << line;
    EXPECT_EQ(mpi["ranks"], 2);
    ASSERT_EQ(mpi["rank_render_ms"].size(), 2u);
    ASSERT_EQ(mpi["rank_points"].size(), 2u);
    EXPECT_EQ(mpi["rank_points"][0].get<double>() + mpi["rank_points"][1].get<double>(), 40000.0);
    EXPECT_EQ(mpi["rank_points"][0].get<double>(), double(pointrast::mpi::rangeOf(40000, 10240, 0, 2).count));
    const double slowest =
        std::max(mpi["rank_render_ms"][0].get<double>(), mpi["rank_render_ms"][1].get<double>());
    EXPECT_EQ(j["median_ms"].get<double>(), slowest);
    EXPECT_GT(slowest, 0.0);
    EXPECT_EQ(mpi["bytes_moved"], 240u * 160u * 8u);
    EXPECT_GE(mpi["composite_ms"].get<double>(), 0.0);
    EXPECT_EQ(mpi["devices"].size(), 2u);
  }
  EXPECT_EQ(results, 2);
  const std::string md = slurp(out / "ranks.md");
  EXPECT_NE(md.find("## Ranks: median GPU time per frame of each rank"), std::string::npos) << md;
  EXPECT_NE(md.find("| terrain-40k | original | overview | batch | 2 | "), std::string::npos) << md;
  const Json report = Json::parse(slurp(out / "ranks.json"), nullptr, false);
  ASSERT_TRUE(report.is_object());
  EXPECT_EQ(report["results"][0]["mpi"]["ranks"], 2);
}

TEST(MpiBench, WhatCannotBeCompositedIsRefusedWithOneLine) {
  REQUIRE_MPI();
  const std::string bench = "-np 2 " + pointrastBinary() + " bench terrain --points 20000 --frames 2 -q ";
  const struct {
    std::string args, line;
  } cases[] = {{"--methods hqs", "pointrast: hqs keeps no closest point per pixel"},
               {"--suite paper2021", "pointrast: --suite runs on one process"}};
  for (const auto& c : cases) {
    const MpiRun r = runMpi(bench + c.args + " --out " + (cliTempDir() / "refused").string());
    EXPECT_EQ(r.exitCode, 1) << c.args << "\n" << r.err;
    EXPECT_EQ(errorLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.line), std::string::npos) << r.err;
  }
}

} // namespace
