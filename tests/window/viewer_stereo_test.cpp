// `pointrast view --stereo` and `--foveated` in a real window on Xvfb (lavapipe, validation layer on): the
// window shows both eyes side by side, each half its width, and equals `render --stereo` at an eye's size bit
// for bit (an uploaded cloud with a batch method; an octree, foveated, once it converged); the panel's
// Stereo and Foveated checkboxes change the image as the options do.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>

#include <gtest/gtest.h>

#include <stb_image.h>

#include "viewer_harness.h"

namespace pointrast::test {
namespace {

// A camera over autzen_trim looking north-east and down, so that most pixels hold points.
const char* kCamera = "--eye 636300,848700,900 --target 636600,849200,450 --up 0,0,1 --fov 60";

std::filesystem::path stereoTempDir() {
  static std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("pointrast_window_stereo_" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

// `pointrast render ARGS --stereo` with each eye `eyeWidth` x `height`: the side-by-side image's pixels.
std::vector<uint32_t> renderStereo(const std::string& args, uint32_t eyeWidth, uint32_t height) {
  const std::filesystem::path out = stereoTempDir() / "reference.png";
  std::filesystem::remove(out);
  const std::string command = "POINTRAST_VALIDATION=1 XDG_RUNTIME_DIR=/tmp '" + pointrastBinary() +
                              "' render " + args + " --width " + std::to_string(eyeWidth) + " --height " +
                              std::to_string(height) + " -o '" + out.string() + "' -q --frames 1";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  int w = 0, h = 0, comp = 0;
  uint8_t* data = stbi_load(out.c_str(), &w, &h, &comp, 4);
  std::vector<uint32_t> pixels;
  if (!data) return pixels;
  EXPECT_EQ(uint32_t(w), 2 * eyeWidth);
  EXPECT_EQ(uint32_t(h), height);
  pixels.resize(size_t(w) * size_t(h));
  std::memcpy(pixels.data(), data, pixels.size() * 4);
  stbi_image_free(data);
  for (uint32_t& p : pixels)
    p |= 0xFF000000u;
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

// Pixels that differ, counting only those `keep` selects (x, y); a size mismatch counts every pixel.
size_t differing(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b, uint32_t width,
                 const std::function<bool(uint32_t, uint32_t)>& keep = {}) {
  if (a.size() != b.size()) return std::max(a.size(), b.size());
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i)
    if (!keep || keep(uint32_t(i % width), uint32_t(i / width))) n += a[i] != b[i];
  return n;
}

// The left and right halves of a side-by-side image differ (the eyes see the cloud from two places).
size_t halvesDiffer(const std::vector<uint32_t>& image, uint32_t width, uint32_t height) {
  size_t n = 0;
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width / 2; ++x)
      n += image[size_t(y) * width + x] != image[size_t(y) * width + width / 2 + x];
  return n;
}

class ViewerStereo : public ::testing::Test {
protected:
  static void SetUpTestSuite() { xvfb_ = new Xvfb(); }
  static void TearDownTestSuite() {
    delete xvfb_;
    xvfb_ = nullptr;
  }
  void SetUp() override {
    ASSERT_FALSE(xvfb_->display().empty()) << "Xvfb did not start (scripts/install-deps.sh installs xvfb)";
    ASSERT_EQ(std::system("command -v xdotool >/dev/null"), 0)
        << "xdotool is missing (scripts/install-deps.sh)";
  }
  std::unique_ptr<Viewer> open(const std::string& args, uint32_t width, uint32_t height) {
    return std::make_unique<Viewer>(
        xvfb_->display(), args + " --width " + std::to_string(width) + " --height " + std::to_string(height) +
                              " --path '" + (stereoTempDir() / "path.json").string() + "'");
  }
  // The window's pixels once they equal `expected` where `keep` says (the X server shows a presented image
  // a moment after the viewer reports it), or the last capture after 20 s.
  Capture captureEqual(Viewer& viewer, const std::vector<uint32_t>& expected, uint32_t width,
                       const std::function<bool(uint32_t, uint32_t)>& keep = {}) {
    Capture shown;
    for (int attempt = 0; attempt < 100; ++attempt) {
      shown = captureWindow(xvfb_->display(), viewer.window());
      if (differing(shown.rgba, expected, width, keep) == 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    return shown;
  }
  void finish(Viewer& viewer) {
    EXPECT_EQ(viewer.quit(), 0) << viewer.errors();
    auto exit = viewer.waitEvent("exit", 0, 5);
    ASSERT_TRUE(exit) << viewer.errors();
    EXPECT_EQ((*exit)["validation_errors"].get<int>(), 0) << viewer.errors();
  }
  static Xvfb* xvfb_;
};
Xvfb* ViewerStereo::xvfb_ = nullptr;

TEST_F(ViewerStereo, BatchMethodShowsBothEyesAsRenderStereoDraws) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  constexpr uint32_t kWidth = 480, kHeight = 240;
  const std::string input = "'" + (dataDir() / "las" / "autzen_trim.las").string() + "' ";
  const std::string options = "--method batch --stereo --ipd 40 --convergence 700";
  auto viewer = open(input + kCamera + " --no-panel " + options, kWidth, kHeight);
  auto first = viewer->waitEvent("frame", 0, 120);
  ASSERT_TRUE(first) << viewer->errors();
  EXPECT_EQ((*first)["options"], options);
  EXPECT_EQ((*first)["width"].get<uint32_t>(), kWidth);
  const std::vector<uint32_t> expected =
      renderStereo(input + cameraOptions((*first)["camera"]) + " " + options, kWidth / 2, kHeight);
  ASSERT_EQ(expected.size(), size_t(kWidth) * kHeight);
  EXPECT_GT(halvesDiffer(expected, kWidth, kHeight), expected.size() / 20) << "the eyes see the same image";
  Capture shown = captureEqual(*viewer, expected, kWidth);
  EXPECT_EQ(differing(shown.rgba, expected, kWidth), 0u);
  finish(*viewer);
}

TEST_F(ViewerStereo, FoveatedOctreeConvergesToRenderStereoFoveated) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default");
  constexpr uint32_t kWidth = 320, kHeight = 240;
  const std::string input = "'" + (dataDir() / "potree" / "autzen_trim_default").string() + "' ";
  const std::string options = "--method lod --min-node-px 30 --stereo --foveated --fovea-radius 0.2";
  auto viewer = open(input + "--no-panel " + options, kWidth, kHeight);
  auto converged = viewer->waitFor(
      [](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && e.contains("lod") && e["lod"].value("converged", false);
      },
      0, 120);
  ASSERT_TRUE(converged) << viewer->errors();
  EXPECT_EQ((*converged)["options"], options);
  const std::string camera = cameraOptions((*converged)["camera"]);
  const std::vector<uint32_t> expected = renderStereo(input + camera + " " + options, kWidth / 2, kHeight);
  ASSERT_EQ(expected.size(), size_t(kWidth) * kHeight);
  Capture shown = captureEqual(*viewer, expected, kWidth);
  EXPECT_EQ(differing(shown.rgba, expected, kWidth), 0u);
  // Foveation draws fewer nodes away from each eye's centre than the same stereo frame without it.
  const std::vector<uint32_t> uniform =
      renderStereo(input + camera + " --method lod --min-node-px 30 --stereo", kWidth / 2, kHeight);
  EXPECT_GT(differing(uniform, expected, kWidth), 0u) << "--foveated changed nothing";
  finish(*viewer);
}

// The panel's checkboxes: Stereo splits the window into two eyes as render --stereo draws them, Foveated
// (on an octree) as render --foveated; outside the panel the window equals render after each click.
TEST_F(ViewerStereo, PanelCheckboxesChangeTheImageAsTheOptionsDo) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default");
  constexpr uint32_t kWidth = 960, kHeight = 640; // room beside the panel
  const std::string input = "'" + (dataDir() / "potree" / "autzen_trim_default").string() + "' ";
  auto viewer = open(input + kCamera + " --min-node-px 30", kWidth, kHeight);
  auto frame = viewer->waitEvent("frame", 0, 120);
  ASSERT_TRUE(frame) << viewer->errors();
  struct Step {
    const char* item;
    const char* expect;
    bool stereo;
  };
  const Step steps[] = {
      {"Stereo", "--method lod --min-node-px 30 --stereo", true},
      {"Foveated", "--method lod --min-node-px 30 --stereo --foveated", true},
      {"Stereo", "--method lod --min-node-px 30 --foveated", false},
  };
  std::vector<uint32_t> before;
  for (const Step& step : steps) {
    ASSERT_TRUE((*frame)["panel_items"].contains(step.item)) << step.item;
    std::vector<float> r = (*frame)["panel_items"][step.item].get<std::vector<float>>();
    size_t from = viewer->eventCount();
    int x = int(r[0] + std::min(8.0f, r[2] / 2)), y = int(r[1] + r[3] / 2);
    viewer->xdotool("mousemove --window $W " + std::to_string(x) + " " + std::to_string(y) + " click 1");
    frame = viewer->waitFor(
        [&](const nlohmann::json& e) {
          return e.value("event", "") == "frame" && e["options"] == step.expect && e.contains("lod") &&
                 e["lod"].value("converged", false);
        },
        from, 90);
    ASSERT_TRUE(frame) << step.item << ": no converged frame with " << step.expect << "\n"
                       << viewer->errors();
    const std::string args = input + cameraOptions((*frame)["camera"]) + " " + step.expect;
    std::vector<uint32_t> expected =
        step.stereo ? renderStereo(args, kWidth / 2, kHeight) : std::vector<uint32_t>{};
    if (!step.stereo) {
      // The mono reference: render --width is the whole window.
      const std::filesystem::path out = stereoTempDir() / "mono.png";
      const std::string command = "POINTRAST_VALIDATION=1 XDG_RUNTIME_DIR=/tmp '" + pointrastBinary() +
                                  "' render " + args + " --width " + std::to_string(kWidth) + " --height " +
                                  std::to_string(kHeight) + " -o '" + out.string() + "' -q --frames 1";
      ASSERT_EQ(std::system(command.c_str()), 0) << command;
      int w = 0, h = 0, comp = 0;
      uint8_t* data = stbi_load(out.c_str(), &w, &h, &comp, 4);
      ASSERT_TRUE(data && uint32_t(w) == kWidth && uint32_t(h) == kHeight);
      expected.resize(size_t(w) * size_t(h));
      std::memcpy(expected.data(), data, expected.size() * 4);
      stbi_image_free(data);
      for (uint32_t& p : expected)
        p |= 0xFF000000u;
    }
    ASSERT_EQ(expected.size(), size_t(kWidth) * kHeight);
    const std::vector<float> panel = (*frame)["panel_items"]["panel"].get<std::vector<float>>();
    auto outside = [&](uint32_t px, uint32_t py) {
      return px > panel[0] + panel[2] + 2 || py > panel[1] + panel[3] + 2;
    };
    Capture shown = captureEqual(*viewer, expected, kWidth, outside);
    EXPECT_EQ(differing(shown.rgba, expected, kWidth, outside), 0u) << step.expect;
    if (!before.empty()) {
      EXPECT_GT(differing(before, expected, kWidth, outside), 0u) << step.expect << " changed nothing";
    }
    before = expected;
  }
  finish(*viewer);
}

} // namespace
} // namespace pointrast::test
