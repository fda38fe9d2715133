// `pointrast view` on octrees (lavapipe, validation layer on): an octree we built, PotreeConverter's own
// (DEFAULT and BROTLI encodings) and a COPC file open with the lod method by default, stream through the
// node cache, and the first converged frame the window shows equals `render --method lod` with the same
// camera bit for bit, also with a node cache a tenth of the octree's size.
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <gtest/gtest.h>

#include <stb_image.h>

#include "viewer_harness.h"

namespace pointrast::test {
namespace {

constexpr uint32_t kWidth = 320, kHeight = 240;

std::filesystem::path lodTempDir() {
  static std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("pointrast_window_lod_" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

std::vector<uint32_t> loadPng(const std::filesystem::path& file, uint32_t& width, uint32_t& height) {
  int w = 0, h = 0, comp = 0;
  uint8_t* data = stbi_load(file.c_str(), &w, &h, &comp, 4);
  std::vector<uint32_t> pixels;
  if (!data) return pixels;
  width = uint32_t(w);
  height = uint32_t(h);
  pixels.resize(size_t(w) * size_t(h));
  std::memcpy(pixels.data(), data, pixels.size() * 4);
  stbi_image_free(data);
  for (uint32_t& p : pixels)
    p |= 0xFF000000u;
  return pixels;
}

// `pointrast render --method lod` of `input` with `args` (the camera and options) at the window's size.
std::vector<uint32_t> renderLod(const std::string& input, const std::string& args) {
  const std::filesystem::path out = lodTempDir() / "reference.png";
  std::filesystem::remove(out);
  const std::string command = "POINTRAST_VALIDATION=1 XDG_RUNTIME_DIR=/tmp '" + pointrastBinary() + "' render '" +
                              input + "' --method lod " + args + " --width " + std::to_string(kWidth) +
                              " --height " + std::to_string(kHeight) + " -o '" + out.string() + "' -q --frames 1";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  uint32_t w = 0, h = 0;
  std::vector<uint32_t> pixels = loadPng(out, w, h);
  EXPECT_EQ(w, kWidth);
  EXPECT_EQ(h, kHeight);
  return pixels;
}

std::string cameraOptions(const nlohmann::json& camera) {
  auto v = [&](const char* key) {
    char text[128];
    const nlohmann::json& j = camera[key];
    std::snprintf(text, sizeof text, "%.17g,%.17g,%.17g", j[0].get<double>(), j[1].get<double>(),
                  j[2].get<double>());
    return std::string(text);
  };
  char fov[64];
  std::snprintf(fov, sizeof fov, "%.17g", camera["fov"].get<double>());
  return "--eye " + v("eye") + " --target " + v("target") + " --up " + v("up") + " --fov " + fov;
}

size_t differing(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
  if (a.size() != b.size()) return std::max(a.size(), b.size());
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i)
    n += a[i] != b[i];
  return n;
}

class ViewerLod : public ::testing::Test {
protected:
  static void SetUpTestSuite() { xvfb_ = new Xvfb(); }
  static void TearDownTestSuite() {
    delete xvfb_;
    xvfb_ = nullptr;
  }
  void SetUp() override {
    ASSERT_FALSE(xvfb_->display().empty()) << "Xvfb did not start (scripts/install-deps.sh installs xvfb)";
  }

  // Opens `input` in the viewer with `args`, waits for its first converged frame, and checks that the
  // window shows exactly what `render --method lod` draws with that frame's camera and `renderArgs`.
  // `reference`: what render draws instead of `input` (the cached octree of a cloud file); `log`: the
  // viewer's stderr, when asked for.
  void expectConvergedFrameEqualsRender(const std::string& input, const std::string& args = "",
                                        const std::string& renderArgs = "", std::string reference = "",
                                        std::string* log = nullptr) {
    SCOPED_TRACE(input + " " + args);
    if (reference.empty()) reference = input;
    Viewer viewer(xvfb_->display(), "'" + input + "' --no-panel " + args + " --width " + std::to_string(kWidth) +
                                        " --height " + std::to_string(kHeight) + " --path '" +
                                        (lodTempDir() / "path.json").string() + "'");
    auto first = viewer.waitEvent("frame", 0, 120);
    ASSERT_TRUE(first) << viewer.errors();
    EXPECT_EQ((*first)["method"], "lod") << "an octree opens with lod";
    ASSERT_TRUE(first->contains("lod")) << first->dump();
    auto converged = viewer.waitFor(
        [](const nlohmann::json& e) {
          return e.value("event", "") == "frame" && e.contains("lod") && e["lod"].value("converged", false);
        },
        0, 120);
    ASSERT_TRUE(converged) << viewer.errors();
    EXPECT_GT((*converged)["lod"]["points_drawn"].get<uint64_t>(), 0u);
    const std::vector<uint32_t> expected = renderLod(reference, cameraOptions((*converged)["camera"]) + " " + renderArgs);
    ASSERT_EQ(expected.size(), size_t(kWidth) * kHeight);
    // The X server shows a presented image a moment after the viewer reports it.
    Capture shown;
    for (int attempt = 0; attempt < 100; ++attempt) {
      shown = captureWindow(xvfb_->display(), viewer.window());
      if (differing(shown.rgba, expected) == 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    EXPECT_EQ(differing(shown.rgba, expected), 0u);
    size_t background = 0;
    for (uint32_t p : expected)
      background += p == 0xFF000000u;
    EXPECT_LT(background, expected.size() * 99 / 100) << "the overview shows the cloud";
    // At rest once converged: no frame follows without input.
    const size_t events = viewer.eventCount();
    auto more = viewer.waitEvent("frame", events, 1.5);
    EXPECT_FALSE(more) << "frames keep coming after the view converged";
    EXPECT_EQ(viewer.quit(), 0) << viewer.errors();
    auto exit = viewer.waitEvent("exit", 0, 5);
    ASSERT_TRUE(exit) << viewer.errors();
    EXPECT_EQ((*exit)["validation_errors"].get<int>(), 0) << viewer.errors();
    if (log) *log = viewer.errors();
  }
  static Xvfb* xvfb_;
};
Xvfb* ViewerLod::xvfb_ = nullptr;

TEST_F(ViewerLod, PotreeDefaultOctreeOpensWithLodAndEqualsRender) {
  expectConvergedFrameEqualsRender((dataDir() / "potree" / "autzen_trim_default").string());
}

TEST_F(ViewerLod, PotreeBrotliOctreeOpensWithLodAndEqualsRender) {
  expectConvergedFrameEqualsRender((dataDir() / "potree" / "autzen_trim_brotli").string());
}

TEST_F(ViewerLod, CopcOpensWithLodAndEqualsRender) {
  expectConvergedFrameEqualsRender((dataDir() / "laz" / "lone-star.copc.laz").string());
}

TEST_F(ViewerLod, BuiltOctreeEqualsRenderAlsoWithATenthOfItsSizeAsNodeCache) {
  const std::filesystem::path octree = lodTempDir() / "autzen_octree";
  std::filesystem::remove_all(octree);
  const std::string build = "'" + pointrastBinary() + "' lod '" + (dataDir() / "las" / "autzen_trim.las").string() +
                            "' -o '" + octree.string() + "' -q";
  ASSERT_EQ(std::system(build.c_str()), 0) << build;
  expectConvergedFrameEqualsRender(octree.string());
  uint64_t bytes = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(octree))
    if (entry.is_regular_file()) bytes += entry.file_size();
  // The overview's selection at --min-node-px 200 (the root) fits a tenth of the octree.
  const std::string budget = "--gpu-memory " + std::to_string(bytes / 10);
  expectConvergedFrameEqualsRender(octree.string(), budget + " --min-node-px 200 --color elevation",
                                   "--min-node-px 200 --color elevation");
}

TEST_F(ViewerLod, CloudLargerThanTheBudgetBuildsItsOctreeIntoTheCacheOnceAndStreamsIt) {
  const std::filesystem::path cache = lodTempDir() / "cache";
  std::filesystem::remove_all(cache);
  setenv("XDG_CACHE_HOME", cache.c_str(), 1); // the viewer's octree cache: cache/pointrast/octrees
  const std::string las = (dataDir() / "las" / "autzen_trim.las").string();
  // 110 k points take 1.7 MB uploaded whole: more than 1 MiB.
  std::string first, second;
  auto cachedOctree = [&] {
    std::string folder;
    if (std::filesystem::is_directory(cache / "pointrast" / "octrees"))
      for (const auto& entry : std::filesystem::directory_iterator(cache / "pointrast" / "octrees"))
        if (entry.is_directory()) folder = entry.path().string();
    return folder;
  };
  const std::string built = [&] {
    // The build happens before the window opens; render then draws the same folder.
    Viewer probe(xvfb_->display(), "'" + las + "' --no-panel --gpu-memory 1M --width 64 --height 48");
    EXPECT_TRUE(probe.waitEvent("frame", 0, 120)) << probe.errors();
    first = probe.errors();
    EXPECT_EQ(probe.quit(), 0) << probe.errors();
    return cachedOctree();
  }();
  ASSERT_FALSE(built.empty()) << first;
  EXPECT_NE(first.find("octree cache: building"), std::string::npos) << first;
  expectConvergedFrameEqualsRender(las, "--gpu-memory 1M", "--gpu-memory 1M", built, &second);
  EXPECT_EQ(second.find("octree cache: building"), std::string::npos) << "the second open reuses it: " << second;
  EXPECT_EQ(cachedOctree(), built);
  unsetenv("XDG_CACHE_HOME");
}

TEST_F(ViewerLod, DamagedNodeMetWhileViewingIsSaidAndTheViewerKeepsRunning) {
  const std::filesystem::path octree = lodTempDir() / "damaged_octree";
  std::filesystem::remove_all(octree);
  const std::string build = "'" + pointrastBinary() + "' lod '" + (dataDir() / "las" / "autzen_trim.las").string() +
                            "' -o '" + octree.string() + "' -q";
  ASSERT_EQ(std::system(build.c_str()), 0) << build;
  Viewer viewer(xvfb_->display(), "'" + octree.string() + "' --no-panel --width " + std::to_string(kWidth) +
                                      " --height " + std::to_string(kHeight));
  auto converged = viewer.waitFor(
      [](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && e.contains("lod") && e["lod"].value("converged", false);
      },
      0, 120);
  ASSERT_TRUE(converged) << viewer.errors();
  // The nodes the overview did not need are gone from the file; zooming in asks for them.
  std::filesystem::resize_file(octree / "octree.bin", 60000);
  const size_t from = viewer.eventCount();
  viewer.xdotool("mousemove --window $W 160 120 click 4 click 4 click 4 click 4 click 4 click 4 click 4");
  auto damaged = viewer.waitFor(
      [](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && e.value("status", "").find("octree.bin") != std::string::npos;
      },
      from, 60);
  ASSERT_TRUE(damaged) << viewer.errors();
  // Still running: a key still gets an answer.
  const size_t later = viewer.eventCount();
  viewer.xdotool("key --window $W c");
  EXPECT_TRUE(viewer.waitEvent("camera", later, 30)) << viewer.errors();
  EXPECT_EQ(viewer.quit(), 0) << viewer.errors();
  auto exit = viewer.waitEvent("exit", 0, 5);
  ASSERT_TRUE(exit) << viewer.errors();
  EXPECT_EQ((*exit)["validation_errors"].get<int>(), 0) << viewer.errors();
}

} // namespace
} // namespace pointrast::test
