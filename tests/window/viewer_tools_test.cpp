// The desktop viewer's tools in a real window on Xvfb (lavapipe, validation layer on): measurements and
// annotations drawn over the window as `render --annotations` draws them over its PNG.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <gtest/gtest.h>

#include <stb_image.h>

#include "cloud/annotations.h"
#include "io/annotations_file.h"
#include "las_records.h"
#include "viewer_harness.h"

namespace pointrast::test {
namespace {

constexpr uint32_t kWidth = 480, kHeight = 360;

// Over autzen_trim looking north-east and down, so that most pixels hold points.
const char* kCamera = "--eye 636300,848700,900 --target 636600,849200,450 --up 0,0,1 --fov 60";

std::string autzen() {
  return (dataDir() / "las" / "autzen_trim.las").string();
}

std::filesystem::path toolsTempDir() {
  static std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("pointrast_window_tools_" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

std::vector<uint32_t> loadRgba(const std::filesystem::path& file, uint32_t& width, uint32_t& height) {
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

// `pointrast render` of autzen_trim with `args` at the window's size: its pixels.
std::vector<uint32_t> renderAutzen(const std::string& args) {
  const std::filesystem::path out = toolsTempDir() / "reference.png";
  std::filesystem::remove(out);
  const std::string command = "POINTRAST_VALIDATION=1 XDG_RUNTIME_DIR=/tmp '" + pointrastBinary() +
                              "' render '" + autzen() + "' " + args + " --width " + std::to_string(kWidth) +
                              " --height " + std::to_string(kHeight) + " -o '" + out.string() +
                              "' -q --frames 1";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  uint32_t w = 0, h = 0;
  std::vector<uint32_t> pixels = loadRgba(out, w, h);
  EXPECT_EQ(w, kWidth);
  EXPECT_EQ(h, kHeight);
  return pixels;
}

double equalFraction(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
  if (a.size() != b.size() || a.empty()) return 0;
  size_t same = 0;
  for (size_t i = 0; i < a.size(); ++i)
    same += a[i] == b[i];
  return double(same) / double(a.size());
}

// Of the pixels where `overlay` differs from `plain` (what the annotations changed), the fraction that
// `shown` has as `overlay` has them.
double overlayMatch(const std::vector<uint32_t>& shown, const std::vector<uint32_t>& overlay,
                    const std::vector<uint32_t>& plain, size_t& changed) {
  changed = 0;
  size_t same = 0;
  if (shown.size() != overlay.size() || plain.size() != overlay.size()) return 0;
  for (size_t i = 0; i < overlay.size(); ++i)
    if (overlay[i] != plain[i]) {
      ++changed;
      same += shown[i] == overlay[i];
    }
  return changed ? double(same) / double(changed) : 0;
}

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

// A distance (three points, one above the ground), a height, an area and a label over the middle of the
// camera's view.
Annotations surveyAnnotations() {
  Annotations a;
  a.unit = "m";
  Annotation distance;
  distance.kind = AnnotationKind::Distance;
  distance.points = {{636450, 849050, 440}, {636650, 849150, 445}, {636700, 849300, 480}};
  Annotation height;
  height.kind = AnnotationKind::Height;
  height.points = {{636500, 849250, 430}, {636560, 849260, 470}};
  height.text = "mast";
  Annotation area;
  area.kind = AnnotationKind::Area;
  area.points = {{636350, 848950, 450}, {636420, 848960, 450}, {636400, 849020, 450}};
  Annotation label;
  label.kind = AnnotationKind::Label;
  label.points = {{636600, 849200, 460}};
  label.text = "survey mark";
  a.items = {distance, height, area, label};
  return a;
}

class ViewerTools : public ::testing::Test {
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
        xvfb_->display(),
        args + " --width " + std::to_string(kWidth) + " --height " + std::to_string(kHeight) + " --path '" +
            (toolsTempDir() / "path.json").string() + "' --screenshot-dir '" + toolsTempDir().string() + "'");
    first_ = viewer->waitEvent("frame", 0, 120);
    EXPECT_TRUE(first_) << viewer->errors();
    return viewer;
  }
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
Xvfb* ViewerTools::xvfb_ = nullptr;

TEST_F(ViewerTools, AnnotationsOverTheWindowEqualRenderAnnotations) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const std::filesystem::path file = toolsTempDir() / "survey.json";
  io::saveAnnotations(file, surveyAnnotations());
  const std::vector<uint32_t> plain = renderAutzen(kCamera);
  const std::vector<uint32_t> expected =
      renderAutzen(std::string(kCamera) + " --annotations '" + file.string() + "'");
  size_t changed = 0;
  overlayMatch(expected, expected, plain, changed);
  // The overlay is there to be seen: lines, markers and labels change a good number of pixels.
  ASSERT_GT(changed, 1500u);
  auto viewer = start("'" + autzen() + "' " + kCamera + " --no-panel --annotations '" + file.string() + "'");
  ASSERT_TRUE(first_);
  Capture shown = captureMatching(display(), viewer->window(), expected, 0.999);
  ASSERT_EQ(shown.width, kWidth);
  ASSERT_EQ(shown.height, kHeight);
  EXPECT_GE(equalFraction(shown.rgba, expected), 0.999);
  EXPECT_GE(overlayMatch(shown.rgba, expected, plain, changed), 0.99);
  // F12's screenshot holds the overlay too.
  const size_t from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 200 200 key F12");
  auto shot = viewer->waitEvent("screenshot", from, 30);
  ASSERT_TRUE(shot) << viewer->errors();
  uint32_t w = 0, h = 0;
  const std::vector<uint32_t> png = loadRgba((*shot)["file"].get<std::string>(), w, h);
  EXPECT_EQ(equalFraction(png, expected), 1.0);
  finish(*viewer);
}

glm::dvec3 vec3(const nlohmann::json& j) {
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

std::string cameraArgs(const nlohmann::json& camera) {
  char text[512];
  const glm::dvec3 e = vec3(camera["eye"]), t = vec3(camera["target"]), u = vec3(camera["up"]);
  std::snprintf(text, sizeof text,
                " --eye %.17g,%.17g,%.17g --target %.17g,%.17g,%.17g --up %.17g,%.17g,%.17g --fov %.17g", e.x,
                e.y, e.z, t.x, t.y, t.z, u.x, u.y, u.z, camera["fov"].get<double>());
  return text;
}

// render --pick of `input` with `options` at a pixel of the window's size with a frame event's camera.
nlohmann::json renderPick(const std::string& input, const std::string& options, const nlohmann::json& camera,
                          const nlohmann::json& pixel) {
  const std::string command =
      "POINTRAST_VALIDATION=1 XDG_RUNTIME_DIR=/tmp '" + pointrastBinary() + "' render '" + input + "'" +
      options + cameraArgs(camera) + " --width " + std::to_string(kWidth) + " --height " +
      std::to_string(kHeight) + " -q --json --frames 1 --pick " + std::to_string(pixel[0].get<int>()) + "," +
      std::to_string(pixel[1].get<int>()) + " -o '" + (toolsTempDir() / "pick.png").string() + "'";
  const nlohmann::json j = nlohmann::json::parse(shellOutput(command), nullptr, false);
  if (!j.is_object() || !j.contains("pick")) {
    ADD_FAILURE() << command;
    return nlohmann::json::object();
  }
  return j["pick"];
}

TEST_F(ViewerTools, CtrlClickOnAnOctreePicksThePointRenderLodPicksAndMeasures) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const std::filesystem::path octree = toolsTempDir() / "autzen_octree";
  std::filesystem::remove_all(octree);
  const std::string build =
      "'" + pointrastBinary() + "' lod '" + autzen() + "' -o '" + octree.string() + "' -q";
  ASSERT_EQ(std::system(build.c_str()), 0) << build;
  auto viewer = start("'" + octree.string() + "' " + kCamera + " --no-panel");
  ASSERT_TRUE(first_);
  auto converged = viewer->waitFor(
      [](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && e.contains("lod") && e["lod"].value("converged", false);
      },
      0, 120);
  ASSERT_TRUE(converged) << viewer->errors();
  const nlohmann::json camera = (*converged)["camera"];
  size_t from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 240 200 keydown ctrl click 1 keyup ctrl");
  auto picked = viewer->waitEvent("picked", from, 30);
  ASSERT_TRUE(picked) << viewer->errors();
  nlohmann::json shown = (*picked)["pick"];
  ASSERT_TRUE(shown["point"].is_object()) << shown.dump();
  EXPECT_TRUE(shown["point"].contains("node")) << shown.dump();
  EXPECT_TRUE(shown["point"].contains("intensity")) << shown.dump();
  // What the octree keeps beyond the record's fields (autzen_trim is LAS point format 3).
  EXPECT_TRUE(shown["point"].contains("gps_time")) << shown.dump();
  EXPECT_TRUE(shown["point"].contains("number_of_returns")) << shown.dump();
  shown.erase("world");
  EXPECT_EQ(shown, renderPick(octree.string(), " --method lod", camera, shown["pixel"]));
  // Ctrl+Shift+click twice: a distance between the two points picked on the octree.
  from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 120 250 keydown ctrl keydown shift click 1 keyup shift keyup ctrl");
  auto a = viewer->waitEvent("picked", from, 30);
  ASSERT_TRUE(a) << viewer->errors();
  from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 380 150 keydown ctrl keydown shift click 1 keyup shift keyup ctrl");
  auto b = viewer->waitEvent("picked", from, 30);
  ASSERT_TRUE(b) << viewer->errors();
  const glm::dvec3 pa = vec3((*a)["pick"]["world"]), pb = vec3((*b)["pick"]["world"]);
  const nlohmann::json list = (*b)["measurements"];
  ASSERT_EQ(list.size(), 1u) << list.dump();
  EXPECT_NEAR(list[0]["value"].get<double>(), glm::length(pa - pb), 1e-9 * glm::length(pa - pb));
  finish(*viewer);
}

TEST_F(ViewerTools, CtrlDragMovesAMeasurementsVertexToThePointUnderTheRelease) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  auto viewer = start("'" + autzen() + "' " + kCamera + " --no-panel");
  ASSERT_TRUE(first_);
  const nlohmann::json camera = (*first_)["camera"];
  size_t from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 120 250 keydown ctrl keydown shift click 1 keyup shift keyup ctrl");
  auto a = viewer->waitEvent("picked", from, 30);
  ASSERT_TRUE(a) << viewer->errors();
  from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 380 150 keydown ctrl keydown shift click 1 keyup shift keyup ctrl");
  auto b = viewer->waitEvent("picked", from, 30);
  ASSERT_TRUE(b) << viewer->errors();
  ASSERT_EQ((*b)["measurements"].size(), 1u);
  // Ctrl+drag from the first vertex (drawn within the pick radius of the first click) to another point.
  from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 120 250 keydown ctrl mousedown 1 mousemove --window $W 160 230 "
                  "mousemove --window $W 200 220 mouseup 1 keyup ctrl");
  auto moved = viewer->waitEvent("moved", from, 30);
  ASSERT_TRUE(moved) << viewer->errors();
  const nlohmann::json& m = (*moved)["moved"];
  ASSERT_TRUE(m["moved"].get<bool>()) << m.dump();
  EXPECT_EQ(m["index"], 0);
  EXPECT_EQ(m["vertex"], 0);
  nlohmann::json pick = m["pick"];
  pick.erase("world");
  EXPECT_EQ(pick, renderPick(autzen(), "", camera, pick["pixel"]));
  const nlohmann::json list = (*moved)["measurements"];
  ASSERT_EQ(list.size(), 1u);
  const glm::dvec3 first = vec3(list[0]["points"][0]), second = vec3(list[0]["points"][1]);
  EXPECT_EQ(first, vec3(m["pick"]["world"]));
  EXPECT_EQ(second, vec3((*b)["pick"]["world"]));
  EXPECT_NEAR(list[0]["value"].get<double>(), glm::length(first - second),
              1e-9 * glm::length(first - second));
  // A Ctrl+drag that starts on no vertex moves nothing.
  from = viewer->eventCount();
  viewer->xdotool("mousemove --window $W 300 300 keydown ctrl mousedown 1 mousemove --window $W 320 310 "
                  "mousemove --window $W 340 320 mouseup 1 keyup ctrl");
  auto missed = viewer->waitEvent("moved", from, 30);
  ASSERT_TRUE(missed) << viewer->errors();
  EXPECT_FALSE((*missed)["moved"]["moved"].get<bool>());
  EXPECT_EQ((*missed)["measurements"], list);
  finish(*viewer);
}

std::vector<std::string> sortedRecords(const std::filesystem::path& file) {
  return sortedLasRecords(file.string());
}

std::optional<nlohmann::json> panelFrame(Viewer& viewer, size_t from, const std::string& item) {
  return viewer.waitFor(
      [&](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && e.contains("panel_items") &&
               e["panel_items"].contains(item);
      },
      from, 30);
}

std::string clickCommand(const nlohmann::json& frame, const std::string& item) {
  const std::vector<float> r = frame["panel_items"][item].get<std::vector<float>>();
  return "mousemove --window $W " + std::to_string(int(r[0] + r[2] / 2)) + " " +
         std::to_string(int(r[1] + r[3] / 2)) + " click 1";
}

void clickItem(Viewer& viewer, const nlohmann::json& frame, const std::string& item) {
  viewer.xdotool(clickCommand(frame, item));
}

TEST_F(ViewerTools, PanelClipBoxExportsWhatConvertClipBoxWrites) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const std::string box = "636400,849000,300,636800,849400,600";
  Viewer viewer(display(), "'" + autzen() + "' " + kCamera + " --width 960 --height 1000 --screenshot-dir '" +
                               toolsTempDir().string() + "'");
  auto frame = viewer.waitEvent("frame", 0, 120);
  ASSERT_TRUE(frame) << viewer.errors();
  ASSERT_TRUE((*frame)["panel_items"].contains("Clip and export")) << (*frame)["panel_items"].dump();
  clickItem(viewer, *frame, "Clip and export");
  // A key that draws a frame, which reports the controls the header opened.
  size_t from = viewer.eventCount();
  viewer.xdotool("mousemove --window $W 950 990 key 8");
  frame = panelFrame(viewer, from, "Export LAS");
  ASSERT_TRUE(frame) << viewer.errors();
  // The text follows the click at once, before the viewer has drawn a frame that saw it: the digits (view
  // keys elsewhere) must still all reach the field the click focused.
  viewer.xdotool(clickCommand(*frame, "box") + " type --delay 5 '" + box + "'");
  from = viewer.eventCount();
  clickItem(viewer, *frame, "Apply");
  // The clipped frame (the clip box is not among the options describeSettings prints).
  auto clipped = panelFrame(viewer, from, "Export LAS");
  ASSERT_TRUE(clipped) << viewer.errors();
  from = viewer.eventCount();
  clickItem(viewer, *clipped, "Export LAS");
  auto exported = viewer.waitEvent("exported", from, 60);
  ASSERT_TRUE(exported) << viewer.errors();
  ASSERT_TRUE(exported->contains("file")) << exported->dump() << viewer.errors();
  EXPECT_GT((*exported)["points"].get<uint64_t>(), 1000u);
  EXPECT_EQ(viewer.quit(), 0) << viewer.errors();
  const std::filesystem::path expected = toolsTempDir() / "convert-clip.las";
  std::filesystem::remove(expected);
  const std::string convert = "'" + pointrastBinary() + "' convert '" + autzen() + "' '" + expected.string() +
                              "' --clip-box " + box + " -q";
  ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
  const std::vector<std::string> mine = sortedRecords((*exported)["file"].get<std::string>());
  EXPECT_EQ(mine.size(), (*exported)["points"].get<uint64_t>());
  EXPECT_TRUE(mine == sortedRecords(expected)) << "the export differs from convert --clip-box";
}

} // namespace
} // namespace pointrast::test
