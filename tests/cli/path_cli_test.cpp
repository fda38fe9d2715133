// `render --path`: a camera path into H.264 video (frame count and size checked by ffprobe) or numbered
// PNG frames (the first equals `render` of the first keyframe, exactly), and no partial output on failure.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "cli_harness.h"

namespace pointrast::test {
namespace {

std::filesystem::path writePath() {
  auto file = cliTempDir() / "path.json";
  std::ofstream(file) << R"({"format": "pointrast-camera-path", "version": 1, "keyframes": [
    {"time": 0, "eye": [636300.25, 848700.5, 900.125], "target": [636600, 849200, 450], "up": [0, 0, 1], "fov": 60},
    {"time": 0.5, "eye": [636900, 848800, 800], "target": [636600, 849200, 450], "up": [0, 0, 1], "fov": 50},
    {"time": 1, "eye": [637000, 849600, 700], "target": [636500, 849200, 450], "up": [0, 0, 1], "fov": 55}]})";
  return file;
}

std::string autzen() {
  return (dataDir() / "las" / "autzen_trim.las").string();
}

std::string shell(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  char buffer[4096];
  size_t n;
  while (pipe && (n = fread(buffer, 1, sizeof buffer, pipe)) > 0)
    out.append(buffer, n);
  if (pipe) pclose(pipe);
  return out;
}

// CI installs ffmpeg and must run this test; elsewhere (a GPU machine without it) it is skipped by name.
bool ffmpegMissingOutsideCi() {
  const char* ci = std::getenv("CI");
  if (ci && std::string(ci) == "true") return false;
  if (const char* bin = std::getenv("POINTRAST_FFMPEG"); bin && *bin) return false;
  return std::system("command -v ffmpeg >/dev/null 2>&1") != 0;
}

TEST(RenderPath, VideoHasEveryFrameAtTheRequestedSize) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  if (ffmpegMissingOutsideCi()) GTEST_SKIP() << "no ffmpeg on this machine (CI runs this test)";
  auto video = cliTempDir() / "fly.mp4";
  std::filesystem::remove(video);
  CliResult r = runPointrast("render '" + autzen() + "' --path '" + writePath().string() + "' --video '" +
                             video.string() + "' --fps 24 --width 320 --height 240 --json -q");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("\"frames\":25"), std::string::npos) << r.out; // 1 s at 24 fps, both ends
  std::string probe = shell("ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                            "stream=nb_read_frames,width,height,codec_name -of csv=p=0 '" +
                            video.string() + "'");
  EXPECT_EQ(probe, "h264,320,240,25\n");
  EXPECT_FALSE(std::filesystem::exists(video.string() + ".partial"));
}

TEST(RenderPath, FirstFrameEqualsRenderOfTheFirstKeyframe) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  auto frames = cliTempDir() / "frames";
  std::filesystem::remove_all(frames);
  CliResult r = runPointrast("render '" + autzen() + "' --path '" + writePath().string() +
                             "' --frames-dir '" + frames.string() + "' --fps 10 --width 320 --height 240 -q");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(frames / "frame_000010.png"));
  EXPECT_FALSE(std::filesystem::exists(frames / "frame_000011.png"));
  auto single = cliTempDir() / "first.png";
  r = runPointrast("render '" + autzen() +
                   "' --eye 636300.25,848700.5,900.125 --target 636600,849200,450 "
                   "--fov 60 --width 320 --height 240 -o '" +
                   single.string() + "' -q");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // The same pixels through the same PNG writer: the same bytes.
  EXPECT_EQ(slurp(frames / "frame_000000.png"), slurp(single));
  EXPECT_NE(slurp(frames / "frame_000001.png"), slurp(single)) << "the camera moves";
}

TEST(RenderPath, FailuresLeaveNoVideo) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  auto video = cliTempDir() / "broken.mp4";
  std::filesystem::remove(video);
  std::string path = writePath().string();
  // ffmpeg that cannot be started, and one that exits at once (the pipe breaks mid-video).
  for (std::string ffmpeg : {"/nonexistent/ffmpeg", "false"}) {
    setenv("POINTRAST_FFMPEG", ffmpeg.c_str(), 1); // inherited by the command runPointrast starts
    CliResult r = runPointrast("render '" + autzen() + "' --path '" + path + "' --video '" + video.string() +
                               "' --fps 24 --width 320 --height 240 -q");
    unsetenv("POINTRAST_FFMPEG");
    EXPECT_EQ(r.exitCode, 1) << ffmpeg;
    EXPECT_FALSE(r.signaled);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(video)) << ffmpeg;
    EXPECT_FALSE(std::filesystem::exists(video.string() + ".partial")) << ffmpeg;
  }
}

TEST(RenderPath, FfmpegMissingFromThePathSaysSoInOneLine) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  auto video = cliTempDir() / "no-ffmpeg.mp4";
  std::filesystem::remove(video);
  std::string path = writePath().string();
  // The default lookup of "ffmpeg" on a PATH that has none (a GPU server without the package).
  const std::string saved = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", cliTempDir().c_str(), 1); // inherited by the command runPointrast starts
  CliResult r = runPointrast("render '" + autzen() + "' --path '" + path + "' --video '" + video.string() +
                             "' --fps 24 --width 320 --height 240 -q");
  setenv("PATH", saved.c_str(), 1);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_FALSE(r.signaled);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("ffmpeg"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--frames-dir"), std::string::npos) << "the way out without ffmpeg: " << r.err;
  EXPECT_FALSE(std::filesystem::exists(video));
  EXPECT_FALSE(std::filesystem::exists(video.string() + ".partial"));
}

TEST(RenderPath, RefusesBadOptionsBeforeLoading) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  std::string path = writePath().string();
  struct Case {
    std::string args, words;
  } cases[] = {
      {"--path '" + path + "'", "exactly one of --video"},
      {"--path '" + path + "' --video a.mp4 --frames-dir d", "exactly one of --video"},
      {"--path '" + path + "' --video a.avi", ".mp4 or .mkv"},
      {"--path '" + path + "' --video a.mp4 --width 321", "even"},
      {"--path '" + path + "' --video a.mp4 --fps 0", "--fps"},
      {"--path '" + path + "' --video a.mp4 -o x.png", "--path replaces -o"},
      {"--video a.mp4 -o x.png", "need --path"},
      {"--path /nonexistent.json --video a.mp4", "no such camera path"},
  };
  for (const Case& c : cases) {
    CliResult r = runPointrast("render '" + autzen() + "' " + c.args + " -q");
    EXPECT_EQ(r.exitCode, 1) << c.args;
    EXPECT_NE(r.err.find(c.words), std::string::npos) << c.args << ": " << r.err;
  }
}

} // namespace
} // namespace pointrast::test
