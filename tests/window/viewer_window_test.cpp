// `pointrast view` in a real window on Xvfb (lavapipe, validation layer on): what the window shows equals
// `render`, mouse input moves the camera by the expected amounts, a double-click picks a point of the cloud,
// the panel changes the image, resizing keeps rendering, and the validation layer stays silent.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <gtest/gtest.h>

#define STB_IMAGE_IMPLEMENTATION
#include <stb_image.h>

#include "cloud/cloud.h"
#include "io/annotations_file.h"
#include "io/reader.h"
#include "io/writer.h"
#include "viewer_harness.h"

namespace pointrast::test {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr uint32_t kWidth = 480, kHeight = 360;

std::string autzen() {
  return (dataDir() / "las" / "autzen_trim.las").string();
}

// A camera over autzen_trim looking north-east and down, so that most pixels hold points.
const char* kCamera = "--eye 636300,848700,900 --target 636600,849200,450 --up 0,0,1 --fov 60";

std::filesystem::path tempDir() {
  static std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("pointrast_window_" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

std::vector<uint32_t> readPng(const std::filesystem::path& file, uint32_t& width, uint32_t& height) {
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

// `pointrast render` with the same input and camera; its pixels.
std::vector<uint32_t> renderReference(const std::string& args, uint32_t width, uint32_t height) {
  std::filesystem::path out = tempDir() / "reference.png";
  std::string command = "POINTRAST_VALIDATION=1 XDG_RUNTIME_DIR=/tmp '" + pointrastBinary() + "' render " +
                        args + " --width " + std::to_string(width) + " --height " + std::to_string(height) +
                        " -o '" + out.string() + "' -q --frames 1";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  uint32_t w = 0, h = 0;
  std::vector<uint32_t> pixels = readPng(out, w, h);
  EXPECT_EQ(w, width);
  EXPECT_EQ(h, height);
  return pixels;
}

double equalFraction(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
  if (a.size() != b.size() || a.empty()) return 0;
  size_t same = 0;
  for (size_t i = 0; i < a.size(); ++i)
    same += a[i] == b[i];
  return double(same) / double(a.size());
}

// The window's pixels once they equal `expected` on at least `fraction` of the pixels (the X server shows a
// presented image a moment after the viewer reports it), or the last capture after `seconds`.
Capture captureMatching(const std::string& display, unsigned long window,
                        const std::vector<uint32_t>& expected, double fraction, double seconds = 20) {
  auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
  Capture capture;
  do {
    capture = captureWindow(display, window);
    if (equalFraction(capture.rgba, expected) >= fraction) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  } while (Clock::now() < deadline);
  return capture;
}

glm::dvec3 vec3(const nlohmann::json& j) {
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

std::string cameraArgs(const nlohmann::json& camera) {
  char text[512];
  glm::dvec3 e = vec3(camera["eye"]), t = vec3(camera["target"]), u = vec3(camera["up"]);
  std::snprintf(text, sizeof text,
                "--eye %.17g,%.17g,%.17g --target %.17g,%.17g,%.17g --up %.17g,%.17g,%.17g --fov %.17g", e.x,
                e.y, e.z, t.x, t.y, t.z, u.x, u.y, u.z, camera["fov"].get<double>());
  return text;
}

class ViewerWindow : public ::testing::Test {
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
  std::unique_ptr<Viewer> start(const std::string& args) {
    auto viewer = std::make_unique<Viewer>(
        xvfb_->display(), args + " --width " + std::to_string(kWidth) + " --height " +
                              std::to_string(kHeight) + " --path '" + (tempDir() / "path.json").string() +
                              "' --screenshot-dir '" + tempDir().string() + "'");
    first_ = viewer->waitEvent("frame", 0, 120);
    EXPECT_TRUE(first_) << viewer->errors();
    return viewer;
  }
  // Escape: exit status 0 and a silent validation layer.
  void finish(Viewer& viewer) {
    EXPECT_EQ(viewer.quit(), 0) << viewer.errors();
    auto exit = viewer.waitEvent("exit", 0, 5);
    ASSERT_TRUE(exit) << viewer.errors();
    EXPECT_EQ((*exit)["validation_errors"].get<int>(), 0) << viewer.errors();
  }
  const std::string& display() const { return xvfb_->display(); }
  static Xvfb* xvfb_;
  std::optional<nlohmann::json> first_;
};
Xvfb* ViewerWindow::xvfb_ = nullptr;

TEST_F(ViewerWindow, ShowsTheSameImageAsRender) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  auto viewer = start("'" + autzen() + "' " + kCamera + " --no-panel");
  ASSERT_TRUE(first_);
  EXPECT_EQ((*first_)["width"].get<uint32_t>(), kWidth);
  EXPECT_EQ((*first_)["height"].get<uint32_t>(), kHeight);
  std::vector<uint32_t> expected =
      renderReference("'" + autzen() + "' " + std::string(kCamera), kWidth, kHeight);
  Capture shown = captureMatching(display(), viewer->window(), expected, 0.999);
  ASSERT_EQ(shown.width, kWidth);
  ASSERT_EQ(shown.height, kHeight);
  EXPECT_GE(equalFraction(shown.rgba, expected), 0.999);
  // The image is not trivially empty: points cover a good part of the window (110 k points, gaps between).
  size_t background = 0;
  for (uint32_t p : expected)
    background += p == 0xFF000000u;
  EXPECT_LT(background, expected.size() * 8 / 10);
  finish(*viewer);
}

TEST_F(ViewerWindow, DragOrbitsAroundThePivotByTheExpectedAngle) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  auto viewer = start("'" + autzen() + "' " + kCamera + " --no-panel");
  ASSERT_TRUE(first_);
  size_t from = viewer->eventCount();
  // 120 px to the right on a 360 px high window: the camera turns by -120/360 * 180 degrees about the
  // vertical through the pivot (the target), clockwise seen from above.
  viewer->xdotool("mousemove --window $W 100 200 mousedown 1 mousemove --window $W 160 200 "
                  "mousemove --window $W 220 200 mouseup 1");
  glm::dvec3 target{636600, 849200, 450}, eye{636300, 848700, 900};
  double angle = -120.0 / kHeight * kPi;
  glm::dvec3 offset = eye - target;
  glm::dvec3 expected =
      target + glm::dvec3(offset.x * std::cos(angle) - offset.y * std::sin(angle),
                          offset.x * std::sin(angle) + offset.y * std::cos(angle), offset.z);
  auto turned = viewer->waitFor(
      [&](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && glm::length(vec3(e["camera"]["eye"]) - expected) < 1e-6;
      },
      from, 30);
  ASSERT_TRUE(turned) << "the camera never reached the expected orbit; last: " << viewer->eventCount();
  EXPECT_NEAR(glm::length(vec3((*turned)["camera"]["target"]) - target), 0, 1e-6);
  // A pan with the right button then moves eye and target by the same vector.
  from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 240 180 mousedown 3 mousemove --window $W 250 180 "
                  "mousemove --window $W 260 180 mouseup 3");
  auto panned = viewer->waitFor(
      [&](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && glm::length(vec3(e["camera"]["target"]) - target) > 1;
      },
      from, 30);
  ASSERT_TRUE(panned);
  glm::dvec3 moveEye = vec3((*panned)["camera"]["eye"]) - expected;
  glm::dvec3 moveTarget = vec3((*panned)["camera"]["target"]) - target;
  EXPECT_LT(glm::length(moveEye - moveTarget), 1e-6);
  finish(*viewer);
}

TEST_F(ViewerWindow, DoubleClickSetsThePivotOnTheClickedPoint) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  auto viewer = start("'" + autzen() + "' " + kCamera + " --no-panel");
  ASSERT_TRUE(first_);
  viewer->xdotool("mousemove --window $W 240 200 click --repeat 2 --delay 60 1");
  auto pick = viewer->waitEvent("pick", 0, 30);
  ASSERT_TRUE(pick) << viewer->errors();
  ASSERT_TRUE((*pick)["hit"].get<bool>());
  glm::dvec3 pivot = vec3((*pick)["pivot"]);
  // The pivot is the position of a cloud point seen within the pick radius of the click, up to one
  // pixel's footprint at its depth (the pivot is that pixel's center at the point's depth).
  PointCloud cloud = io::readCloud(autzen());
  double nearest = 1e30;
  for (uint64_t i = 0; i < cloud.size(); ++i)
    nearest = std::min(nearest, glm::length(cloud.world(i) - pivot));
  glm::dvec3 eye{636300, 848700, 900};
  double footprint = 2 * glm::length(pivot - eye) * std::tan(kPi / 6) / kHeight;
  EXPECT_LE(nearest, footprint) << "footprint " << footprint;
  EXPECT_GT((*pick)["x"].get<double>(), 239);
  // The next orbit turns around the new pivot: it stays where it is.
  size_t from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 100 100 mousedown 1 mousemove --window $W 180 100 mouseup 1");
  auto turned = viewer->waitEvent("frame", from, 30);
  ASSERT_TRUE(turned);
  EXPECT_LT(glm::length(vec3((*turned)["pivot"]) - pivot), 1e-9);
  finish(*viewer);
}

// render --pick at a pixel of a kWidth x kHeight image with a frame event's camera: its "pick" object.
nlohmann::json renderPick(const nlohmann::json& camera, int x, int y) {
  const std::string command =
      "POINTRAST_VALIDATION=1 '" + pointrastBinary() + "' render '" + autzen() + "' " + cameraArgs(camera) +
      " --width " + std::to_string(kWidth) + " --height " + std::to_string(kHeight) + " -q --json --pick " +
      std::to_string(x) + "," + std::to_string(y) + " -o '" + (tempDir() / "pick.png").string() + "'";
  std::string out;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char buffer[4096];
    size_t n = 0;
    while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0)
      out.append(buffer, n);
    pclose(pipe);
  }
  nlohmann::json j = nlohmann::json::parse(out, nullptr, false);
  if (!j.is_object() || !j.contains("pick")) {
    ADD_FAILURE() << command << " printed " << out;
    return nlohmann::json::object();
  }
  return j["pick"];
}

TEST_F(ViewerWindow, CtrlClickPicksThePointRenderPicksAndMeasurementsSaveAndLoad) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const std::filesystem::path file = tempDir() / "measured.json";
  std::filesystem::remove(file);
  auto viewer = start("'" + autzen() + "' " + kCamera + " --no-panel --annotations '" + file.string() + "'");
  ASSERT_TRUE(first_);
  const nlohmann::json camera = (*first_)["camera"];
  viewer->xdotool("mousemove --window $W 240 200 keydown ctrl click 1 keyup ctrl");
  auto picked = viewer->waitEvent("picked", 0, 30);
  ASSERT_TRUE(picked) << viewer->errors();
  nlohmann::json shown = (*picked)["pick"];
  shown.erase("world");
  const nlohmann::json expected = renderPick(camera, 240, 200);
  ASSERT_TRUE(expected["point"].is_object()) << expected.dump();
  EXPECT_EQ(shown, expected);
  EXPECT_EQ((*picked)["measurements"], nlohmann::json::array()) << "a plain Ctrl+click measures nothing";
  // Ctrl+Shift+click twice: a distance between the two picked points, saved by Ctrl+S.
  size_t from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 120 250 keydown ctrl keydown shift click 1 keyup shift keyup ctrl");
  auto a = viewer->waitEvent("picked", from, 30);
  ASSERT_TRUE(a);
  from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 380 150 keydown ctrl keydown shift click 1 keyup shift keyup ctrl");
  auto b = viewer->waitEvent("picked", from, 30);
  ASSERT_TRUE(b);
  const glm::dvec3 pa = vec3((*a)["pick"]["world"]), pb = vec3((*b)["pick"]["world"]);
  const nlohmann::json list = (*b)["measurements"];
  ASSERT_EQ(list.size(), 1u) << list.dump();
  EXPECT_NEAR(list[0]["value"].get<double>(), glm::length(pa - pb), 1e-9 * glm::length(pa - pb));
  from = viewer->eventCount();
  viewer->xdotool("key ctrl+s");
  auto saved = viewer->waitEvent("annotations", from, 30);
  ASSERT_TRUE(saved) << viewer->errors();
  EXPECT_EQ((*saved)["count"], 1);
  finish(*viewer);
  // The file holds the two points; a viewer started with it lists the same measurement.
  Annotations loaded = io::loadAnnotations(file);
  ASSERT_EQ(loaded.items.size(), 1u);
  EXPECT_EQ(loaded.items[0].kind, AnnotationKind::Distance);
  ASSERT_EQ(loaded.items[0].points.size(), 2u);
  EXPECT_EQ(loaded.items[0].points[0], pa);
  EXPECT_EQ(loaded.items[0].points[1], pb);
  auto again = start("'" + autzen() + "' " + kCamera + " --no-panel --annotations '" + file.string() + "'");
  ASSERT_TRUE(first_);
  again->xdotool("mousemove --window $W 240 200 keydown ctrl click 1 keyup ctrl");
  auto listed = again->waitEvent("picked", 0, 30);
  ASSERT_TRUE(listed);
  ASSERT_EQ((*listed)["measurements"].size(), 1u);
  EXPECT_EQ((*listed)["measurements"][0]["value"], list[0]["value"]);
  finish(*again);
}

TEST_F(ViewerWindow, PanelControlChangesTheImage) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  auto viewer = start("'" + autzen() + "' " + kCamera);
  ASSERT_TRUE(first_);
  ASSERT_TRUE((*first_)["panel"].get<bool>());
  ASSERT_TRUE((*first_)["panel_items"].contains("White"));
  std::vector<float> white = (*first_)["panel_items"]["White"].get<std::vector<float>>();
  Capture before = captureWindow(display(), viewer->window());
  size_t from = viewer->eventCount();
  int x = int(white[0] + 8), y = int(white[1] + white[3] / 2);
  viewer->xdotool("mousemove --window $W " + std::to_string(x) + " " + std::to_string(y) + " click 1");
  auto changed = viewer->waitFor(
      [](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && e["background"].get<uint32_t>() == 0xFFFFFFFFu;
      },
      from, 30);
  ASSERT_TRUE(changed) << viewer->errors();
  // The background outside the panel turned white: the sky above the cloud and the gaps between points.
  // (The X server shows a presented image a moment after the viewer reports it: captured until it shows.)
  Capture after;
  size_t whiteNow = 0;
  const auto deadline = Clock::now() + std::chrono::seconds(20);
  do {
    after = captureWindow(display(), viewer->window());
    whiteNow = 0;
    for (uint32_t p : after.rgba)
      whiteNow += p == 0xFFFFFFFFu;
    if (whiteNow > after.rgba.size() / 20) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  } while (Clock::now() < deadline);
  ASSERT_EQ(after.rgba.size(), before.rgba.size());
  EXPECT_LT(equalFraction(before.rgba, after.rgba), 0.9);
  EXPECT_GT(whiteNow, after.rgba.size() / 20);
  finish(*viewer);
}

// Where a window's pixels outside the panel differ from the expected image: their count and bounding box.
std::string whereTheyDiffer(const Capture& shown, const std::vector<uint32_t>& expected,
                            const std::vector<float>& panel) {
  if (shown.rgba.size() != expected.size())
    return "the window is " + std::to_string(shown.width) + "x" + std::to_string(shown.height);
  uint32_t x0 = shown.width, y0 = shown.height, x1 = 0, y1 = 0, count = 0;
  for (uint32_t y = 0; y < shown.height; ++y)
    for (uint32_t x = 0; x < shown.width; ++x) {
      const size_t i = size_t(y) * shown.width + x;
      if (!(x > panel[0] + panel[2] + 2 || y > panel[1] + panel[3] + 2) || shown.rgba[i] == expected[i])
        continue;
      ++count;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  return std::to_string(count) + " pixels differ in x " + std::to_string(x0) + "-" + std::to_string(x1) +
         ", y " + std::to_string(y0) + "-" + std::to_string(y1) + " (panel " + std::to_string(int(panel[2])) +
         "x" + std::to_string(int(panel[3])) + ")";
}

// Each panel control changes the image as `render` with its option does: after each click the window,
// outside the panel, equals render with the options the frame reports, and differs from the image before.
TEST_F(ViewerWindow, PanelControlsChangeTheImageAsRenderOptionsDo) {
  constexpr uint32_t kBigWidth = 960, kBigHeight = 720; // room beside the panel
  auto viewer = std::make_unique<Viewer>(
      display(), "'" + autzen() + "' " + kCamera + " --width " + std::to_string(kBigWidth) + " --height " +
                     std::to_string(kBigHeight) + " --path '" + (tempDir() / "path.json").string() + "'");
  std::optional<nlohmann::json> frame = viewer->waitEvent("frame", 0, 120);
  ASSERT_TRUE(frame) << viewer->errors();
  struct Step {
    const char* item;
    const char* expect;
    bool compare = true; // false: a step on the way to the next one, only waited for
  };
  const Step steps[] = {
      {"Intensity", "--color intensity"},
      {"Point size +", "--color intensity --point-size 2", false},
      {"Point size +", "--color intensity --point-size 3"},
      {"EDL", "--color intensity --point-size 3 --edl"},
      {"Dilation +", "--color intensity --point-size 3 --dilate 1 --edl", false},
      {"Dilation +", "--color intensity --point-size 3 --dilate 2 --edl"},
      {"Classification", "--color classification --point-size 3 --dilate 2 --edl"},
  };
  std::vector<uint32_t> before = renderReference("'" + autzen() + "' " + kCamera, kBigWidth, kBigHeight);
  for (const Step& step : steps) {
    ASSERT_TRUE((*frame)["panel_items"].contains(step.item)) << step.item;
    std::vector<float> r = (*frame)["panel_items"][step.item].get<std::vector<float>>();
    std::vector<float> panel = (*frame)["panel_items"]["panel"].get<std::vector<float>>();
    size_t from = viewer->eventCount();
    int x = int(r[0] + std::min(8.0f, r[2] / 2)), y = int(r[1] + r[3] / 2);
    viewer->xdotool("mousemove --window $W " + std::to_string(x) + " " + std::to_string(y) + " click 1");
    frame = viewer->waitFor(
        [&](const nlohmann::json& e) {
          return e.value("event", "") == "frame" && e["options"] == step.expect;
        },
        from, 60);
    ASSERT_TRUE(frame) << step.item << ": no frame with " << step.expect << "\n" << viewer->errors();
    if (!step.compare) continue;
    std::vector<uint32_t> expected =
        renderReference("'" + autzen() + "' " + kCamera + " " + step.expect, kBigWidth, kBigHeight);
    // Outside the panel (as it was drawn at the click, and is now: the larger of the two).
    panel[2] = std::max(panel[2], (*frame)["panel_items"]["panel"][2].get<float>());
    panel[3] = std::max(panel[3], (*frame)["panel_items"]["panel"][3].get<float>());
    auto outside = [&](const std::vector<uint32_t>& image) {
      std::vector<uint32_t> pixels;
      for (uint32_t py = 0; py < kBigHeight; ++py)
        for (uint32_t px = 0; px < kBigWidth; ++px)
          if (px > panel[0] + panel[2] + 2 || py > panel[1] + panel[3] + 2)
            pixels.push_back(image[size_t(py) * kBigWidth + px]);
      return pixels;
    };
    std::vector<uint32_t> want = outside(expected);
    ASSERT_GT(want.size(), size_t(kBigWidth) * kBigHeight / 4) << "the panel covers most of the window";
    auto deadline = Clock::now() + std::chrono::seconds(20);
    double same = 0;
    Capture shown;
    do {
      // The panel may have grown since (its lines of times are longer on a loaded machine): what it
      // covered in any frame since the click stays out of the comparison.
      viewer->waitFor(
          [&](const nlohmann::json& e) {
            if (e.value("event", "") == "frame" && e.contains("panel_items")) {
              panel[2] = std::max(panel[2], e["panel_items"]["panel"][2].get<float>());
              panel[3] = std::max(panel[3], e["panel_items"]["panel"][3].get<float>());
            }
            return false;
          },
          from, 0);
      want = outside(expected);
      shown = captureWindow(display(), viewer->window());
      if (shown.rgba.size() == expected.size()) same = equalFraction(outside(shown.rgba), want);
      if (same >= 0.999) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    } while (Clock::now() < deadline);
    EXPECT_GE(same, 0.999) << step.expect << "; " << whereTheyDiffer(shown, expected, panel);
    EXPECT_LT(equalFraction(outside(before), want), 0.98) << step.expect << " changed nothing";
    before = expected;
  }
  // C prints the camera and these settings as render options.
  size_t from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 900 700 key c");
  auto camera = viewer->waitEvent("camera", from, 30);
  ASSERT_TRUE(camera);
  EXPECT_EQ((*camera)["options"], steps[std::size(steps) - 1].expect);
  finish(*viewer);
}

// An octree with eye-dome lighting: the panel shows and the LOD method converges to an image of the cloud.
// The window is kept as a PNG (in $POINTRAST_DOCS_DIR as viewer-lod.png when set: the picture in docs/).
TEST_F(ViewerWindow, AnOctreeWithEdlConvergesWithThePanelShown) {
  const std::string octree = (dataDir() / "potree" / "autzen_trim_default").string();
  constexpr uint32_t kShotWidth = 1100, kShotHeight = 760;
  auto viewer = std::make_unique<Viewer>(display(), "'" + octree + "' " + kCamera + " --edl --width " +
                                                        std::to_string(kShotWidth) + " --height " +
                                                        std::to_string(kShotHeight));
  auto converged = viewer->waitFor(
      [](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && e.contains("lod") && e["lod"].value("converged", false);
      },
      0, 120);
  ASSERT_TRUE(converged) << viewer->errors();
  EXPECT_EQ((*converged)["options"], "--method lod --edl");
  ASSERT_TRUE((*converged)["panel_items"].contains("EDL"));
  std::vector<float> panel = (*converged)["panel_items"]["panel"].get<std::vector<float>>();
  // The X server shows the presented image a moment later: wait until points appear beside the panel.
  Capture shown;
  size_t lit = 0;
  auto deadline = Clock::now() + std::chrono::seconds(20);
  do {
    shown = captureWindow(display(), viewer->window());
    lit = 0;
    for (uint32_t y = 0; y < shown.height; ++y)
      for (uint32_t x = uint32_t(panel[0] + panel[2]) + 2; x < shown.width; ++x)
        lit += shown.rgba[size_t(y) * shown.width + x] != 0xFF000000u;
    if (lit > size_t(kShotWidth) * kShotHeight / 40) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  } while (Clock::now() < deadline);
  ASSERT_EQ(shown.width, kShotWidth);
  EXPECT_GT(lit, size_t(kShotWidth) * kShotHeight / 40) << "no cloud beside the panel";
  std::filesystem::path out = tempDir() / "viewer-lod.png";
  if (const char* docs = std::getenv("POINTRAST_DOCS_DIR"))
    out = std::filesystem::path(docs) / "viewer-lod.png";
  io::writePng(out, shown.width, shown.height, shown.rgba.data());
  finish(*viewer);
}

TEST_F(ViewerWindow, ResizingKeepsRenderingTheSameCamera) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  auto viewer = start("'" + autzen() + "' " + kCamera + " --no-panel");
  ASSERT_TRUE(first_);
  size_t from = viewer->eventCount();
  viewer->xdotool("windowsize --sync $W 400 300");
  auto resized = viewer->waitFor(
      [](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && e["width"] == 400 && e["height"] == 300;
      },
      from, 30);
  ASSERT_TRUE(resized) << viewer->errors();
  std::vector<uint32_t> expected =
      renderReference("'" + autzen() + "' " + cameraArgs((*resized)["camera"]), 400, 300);
  Capture shown = captureMatching(display(), viewer->window(), expected, 0.999);
  EXPECT_GE(equalFraction(shown.rgba, expected), 0.999);
  finish(*viewer);
}

TEST_F(ViewerWindow, KeysRecordKeyframesAndScreenshots) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  std::filesystem::remove(tempDir() / "path.json");
  auto viewer = start("'" + autzen() + "' " + kCamera + " --no-panel");
  ASSERT_TRUE(first_);
  viewer->xdotool("mousemove --window $W 200 200 key k key 8 key k key F12");
  auto shot = viewer->waitEvent("screenshot", 0, 30);
  ASSERT_TRUE(shot) << viewer->errors();
  uint32_t w = 0, h = 0;
  EXPECT_FALSE(readPng((*shot)["file"].get<std::string>(), w, h).empty());
  EXPECT_EQ(w, kWidth);
  EXPECT_EQ(h, kHeight);
  auto saved = viewer->waitFor(
      [](const nlohmann::json& e) { return e.value("event", "") == "keyframes" && e["count"] == 2; }, 0, 30);
  ASSERT_TRUE(saved);
  finish(*viewer);
  std::string json = shellOutput("cat '" + (tempDir() / "path.json").string() + "'");
  EXPECT_NE(json.find("pointrast-camera-path"), std::string::npos);
  EXPECT_NE(json.find("636300"), std::string::npos) << "the first keyframe is the starting camera";
}

// Turns the camera to the top and the front view in turn (keys 8 and 5, which reach the viewer wherever the
// panel is), each key waiting for the frame it causes, until `frames` more frames were rendered; returns
// whether they all came.
bool renderFrames(Viewer& viewer, int frames) {
  viewer.xdotool("mousemove --window $W " + std::to_string(kWidth - 4) + " " + std::to_string(kHeight - 4));
  for (int i = 1; i <= frames; ++i) {
    size_t from = viewer.eventCount();
    viewer.xdotool(i % 2 ? "key 8" : "key 5");
    if (!viewer.waitEvent("frame", from, 30)) return false;
  }
  return true;
}

TEST_F(ViewerWindow, StatsFileHasTheGpuTimeOfEveryPassOverTheFramesRendered) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  constexpr int kFrames = 12;
  std::filesystem::path stats = tempDir() / "stats.json";
  std::filesystem::remove(stats);
  auto viewer = start("'" + autzen() + "' " + kCamera + " --stats '" + stats.string() + "'");
  ASSERT_TRUE(first_);
  ASSERT_TRUE(renderFrames(*viewer, kFrames)) << viewer->errors();
  EXPECT_FALSE(std::filesystem::exists(stats)) << "written as the window closes, not before";
  finish(*viewer);
  auto exit = viewer->waitEvent("exit", 0, 5);
  ASSERT_TRUE(exit);
  ASSERT_TRUE(std::filesystem::exists(stats)) << viewer->errors();
  EXPECT_FALSE(std::filesystem::exists(stats.string() + ".partial"));
  nlohmann::json j = nlohmann::json::parse(shellOutput("cat '" + stats.string() + "'"), nullptr, false);
  ASSERT_TRUE(j.is_object());
  // Every frame the session rendered: the first, one per drag step, and those the panel's look asked for.
  EXPECT_GE(j["frames"].get<int>(), kFrames + 1);
  EXPECT_EQ(j["frames"], (*exit)["frames"]);
  EXPECT_EQ(j["methods"], nlohmann::json({"atomicmin"}));
  EXPECT_EQ(j["sizes"], nlohmann::json({std::to_string(kWidth) + "x" + std::to_string(kHeight)}));
  EXPECT_FALSE(j["device"]["name"].get<std::string>().empty());
  EXPECT_FALSE(j["commit"].get<std::string>().empty());
  EXPECT_GT(j["wall_seconds"].get<double>(), 0);
  auto ms = [&](const char* group, const char* item, const char* figure) {
    return j[group][item][figure].get<double>();
  };
  for (const char* pass : {"render", "present"}) {
    EXPECT_GT(ms("passes", pass, "min_ms"), 0) << pass;
    EXPECT_LE(ms("passes", pass, "median_ms"), ms("passes", pass, "p95_ms")) << pass;
    EXPECT_LE(ms("passes", pass, "p95_ms"), ms("passes", pass, "max_ms")) << pass;
    // A pass is part of the frame's GPU time, frame after frame, so its percentiles are too.
    EXPECT_LE(ms("passes", pass, "median_ms"), ms("frame", "gpu", "median_ms")) << pass;
  }
  // At least half the frames take the median render time or more, plus at least the least present time.
  EXPECT_LE(ms("passes", "render", "median_ms") + ms("passes", "present", "min_ms"),
            ms("frame", "gpu", "median_ms"));
  // The passes run one after the other, each waited for: their sum stays within the host's frame time.
  EXPECT_LE(ms("frame", "gpu", "median_ms"), ms("frame", "host", "median_ms"));
  EXPECT_LE(ms("frame", "gpu", "p95_ms"), ms("frame", "host", "p95_ms"));
  EXPECT_LE(ms("frame", "gpu", "max_ms"), ms("frame", "host", "max_ms"));
}

TEST_F(ViewerWindow, StatsGoToStdoutAsOneLineAfterTheExit) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  auto viewer = start("'" + autzen() + "' " + kCamera + " --no-panel --stats -");
  ASSERT_TRUE(first_);
  ASSERT_TRUE(renderFrames(*viewer, 3)) << viewer->errors();
  finish(*viewer);
  auto stats = viewer->waitFor([](const nlohmann::json& e) { return e.contains("passes"); }, 0, 5);
  ASSERT_TRUE(stats) << viewer->errors();
  EXPECT_GE((*stats)["frames"].get<int>(), 4);
  EXPECT_EQ((*stats)["panel"], false);
  EXPECT_GT((*stats)["passes"]["render"]["median_ms"].get<double>(), 0);
}

TEST_F(ViewerWindow, StatsThatCannotBeWrittenFailBeforeTheWindowOpens) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  // A folder that is not there, and a folder where the file should be.
  for (std::string stats : {std::string("/nonexistent/folder/stats.json"), tempDir().string()}) {
    std::string command = "DISPLAY=" + display() + " '" + pointrastBinary() + "' view '" + autzen() +
                          "' --stats '" + stats + "' 2>&1; echo \"exit=$?\"";
    std::string out = shellOutput(command);
    EXPECT_NE(out.find("--stats"), std::string::npos) << out;
    EXPECT_NE(out.find("exit=1"), std::string::npos) << out;
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 2) << "one line, then the exit status: " << out;
  }
}

TEST(ViewerWithoutDisplay, SaysSoInOneLineAndExits1) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  std::string command = "env -u DISPLAY -u WAYLAND_DISPLAY '" + pointrastBinary() + "' view '" + autzen() +
                        "' 2>&1; echo \"exit=$?\"";
  std::string out = shellOutput(command);
  EXPECT_NE(out.find("no display"), std::string::npos) << out;
  EXPECT_NE(out.find("pointrast serve"), std::string::npos) << out;
  EXPECT_NE(out.find("exit=1"), std::string::npos) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 2) << "one line, then the exit status: " << out;
}

} // namespace
} // namespace pointrast::test
