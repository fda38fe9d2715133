// The desktop viewer's profile panel in a real window on Xvfb (lavapipe, validation layer on): a line drawn
// on picked points or typed in the panel gives the picture, the LAS and the CSV that `pointrast profile`
// writes for that line and width, and the Profile window shows that picture pixel for pixel.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>

#include <gtest/gtest.h>

#include <stb_image.h>

#include "io/writer.h"
#include "las_records.h"
#include "viewer_harness.h"

namespace pointrast::test {
namespace {

// Over autzen_trim looking north-east and down.
const char* kCamera = "--eye 636300,848700,900 --target 636600,849200,450 --up 0,0,1 --fov 60";
const char* kLine = "636400,849000,636800,849400,636900,849300";
const char* kWidth = "6";

std::filesystem::path profileTempDir() {
  static std::filesystem::path dir = [] {
    auto d =
        std::filesystem::temp_directory_path() / ("pointrast_window_profile_" + std::to_string(getpid()));
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
  return pixels;
}

std::vector<std::string> sortedRecords(const std::filesystem::path& file) {
  return sortedLasRecords(file.string());
}

// A wheel step over the ground (in, then out) zooms and redraws the scene, and the frame it reports lists the
// panel's controls where they are now: every input sent before it has been seen. Its camera tells it from a
// frame rendered before the step (whose panel may predate the last click). The wheel leaves a text field that
// is being edited as it is.
std::optional<nlohmann::json> redraw(Viewer& viewer, const nlohmann::json& previous,
                                     const std::string& item) {
  static bool in = false;
  in = !in;
  const size_t from = viewer.eventCount();
  viewer.xdotool(std::string("mousemove --window $W 900 560 click ") + (in ? "4" : "5"));
  auto r = viewer.waitFor(
      [&](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && e["camera"] != previous["camera"] &&
               e.contains("panel_items") && e["panel_items"].contains(item);
      },
      from, 30);
  return r;
}

void clickItem(Viewer& viewer, const nlohmann::json& frame, const std::string& item) {
  const std::vector<float> r = frame["panel_items"][item].get<std::vector<float>>();
  viewer.xdotool("mousemove --window $W " + std::to_string(int(r[0] + r[2] / 2)) + " " +
                 std::to_string(int(r[1] + r[3] / 2)) + " click 1");
}

std::optional<nlohmann::json> redraw(Viewer& viewer, const nlohmann::json& previous, const std::string& item);

// Clicks a panel button and returns the profile event it leads to, once a frame has shown the release.
std::optional<nlohmann::json> press(Viewer& viewer, std::optional<nlohmann::json>& frame,
                                    const std::string& item) {
  const size_t from = viewer.eventCount();
  clickItem(viewer, *frame, item);
  auto event = viewer.waitEvent("profile", from, 60);
  if (event) frame = redraw(viewer, *frame, item);
  return frame ? event : std::nullopt;
}

// A Ctrl+Shift+click in the view: the picked point becomes the next vertex of a distance measurement.
std::optional<nlohmann::json> addVertex(Viewer& viewer, int x, int y) {
  const size_t from = viewer.eventCount();
  viewer.xdotool("mousemove --window $W " + std::to_string(x) + " " + std::to_string(y) +
                 " keydown ctrl keydown shift click 1 keyup shift keyup ctrl");
  return viewer.waitEvent("picked", from, 30);
}

class ViewerProfile : public ::testing::Test {
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
  static Xvfb* xvfb_;
};
Xvfb* ViewerProfile::xvfb_ = nullptr;

// `pointrast profile` of `input` with a line and width: the picture at `size`, the LAS and the CSV.
void cliProfile(const std::string& input, const std::string& line, const std::string& width,
                const std::string& size, const std::filesystem::path& dir) {
  const std::string command = "'" + pointrastBinary() + "' profile '" + input + "' --line " + line +
                              " --width " + width + " --size " + size + " -o '" + (dir / "cli.png").string() +
                              "' --las '" + (dir / "cli.las").string() + "' --csv '" +
                              (dir / "cli.csv").string() + "' -q";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
}

std::vector<std::string> sortedLines(const std::filesystem::path& file) {
  std::vector<std::string> lines;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  std::sort(lines.begin(), lines.end());
  return lines;
}

// Opens `input` in the viewer, draws a profile line (typed when `line` is given, else picked as a distance
// measurement and taken with "From measurement"), cuts it at kWidth, exports it, and checks the picture,
// the LAS and the CSV against `pointrast profile`, and the Profile window's pixels against the picture.
void checkPanelProfile(const std::string& display, const std::string& input, const std::string& name,
                       const char* line) {
  const std::filesystem::path dir = profileTempDir() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  Viewer viewer(display, "'" + input + "' " + kCamera + " --width 1200 --height 1000 --screenshot-dir '" +
                             dir.string() + "' --path '" + (dir / "path.json").string() + "'");
  // The first frame that is complete (an octree's refines over several), so that the panel holds still.
  auto frame = viewer.waitFor(
      [](const nlohmann::json& e) {
        return e.value("event", "") == "frame" && (!e.contains("lod") || e["lod"].value("converged", false));
      },
      0, 120);
  ASSERT_TRUE(frame) << viewer.errors();
  if (!line) {
    // Two pixels where the camera sees the ground, right of the panel.
    ASSERT_TRUE(addVertex(viewer, 620, 680)) << viewer.errors();
    const auto b = addVertex(viewer, 900, 560);
    ASSERT_TRUE(b) << viewer.errors();
    ASSERT_EQ((*b)["measurements"].size(), 1u) << b->dump();
  }
  // Two sections closed, so that the open Profile section fits in the window below the octree's statistics.
  for (const char* section : {"Look", "Stereo and foveation"}) {
    frame = redraw(viewer, *frame, section);
    ASSERT_TRUE(frame) << viewer.errors();
    clickItem(viewer, *frame, section);
  }
  frame = redraw(viewer, *frame, "Profile");
  ASSERT_TRUE(frame) << viewer.errors();
  clickItem(viewer, *frame, "Profile");
  frame = redraw(viewer, *frame, "Cut");
  ASSERT_TRUE(frame) << viewer.errors();
  for (const char* item :
       {"line", "width", "Cut", "profile file", "Profile LAS", "Profile CSV", "Profile PNG"}) {
    const std::vector<float> r = (*frame)["panel_items"][item].get<std::vector<float>>();
    ASSERT_LE(r[1] + r[3], 1000) << item << " is below the window's bottom";
  }
  // Each click and each text typed is seen (a frame drawn) before the next.
  const auto type = [&](const std::string& field, const std::string& text, bool select) {
    clickItem(viewer, *frame, field);
    frame = redraw(viewer, *frame, field);
    ASSERT_TRUE(frame) << viewer.errors();
    viewer.xdotool(std::string(select ? "key ctrl+a " : "") + "type --delay 20 '" + text + "'");
    frame = redraw(viewer, *frame, field);
    ASSERT_TRUE(frame) << viewer.errors();
  };
  if (line) {
    type("line", line, false);
    ASSERT_FALSE(::testing::Test::HasFatalFailure());
    type("profile file", (dir / "typed").string(), false);
  } else {
    clickItem(viewer, *frame, "From measurement");
    frame = redraw(viewer, *frame, "From measurement");
    ASSERT_TRUE(frame) << viewer.errors();
  }
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  type("width", kWidth, true);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  const auto cut = press(viewer, frame, "Cut");
  ASSERT_TRUE(cut) << viewer.errors();
  ASSERT_FALSE(cut->contains("error")) << cut->dump();
  const std::string drawn = (*cut)["line"];
  if (line) {
    EXPECT_EQ(drawn, line);
  }
  EXPECT_EQ((*cut)["strip_width"].get<double>(), std::stod(kWidth));
  EXPECT_GT((*cut)["points"].get<uint64_t>(), 100u);
  const uint32_t width = (*cut)["width"], height = (*cut)["height"];
  frame = redraw(viewer, *frame, "profile image");
  ASSERT_TRUE(frame) << viewer.errors();
  const auto png = press(viewer, frame, "Profile PNG");
  ASSERT_TRUE(png && png->contains("file")) << (png ? png->dump() : "") << viewer.errors();
  const auto las = press(viewer, frame, "Profile LAS");
  ASSERT_TRUE(las && las->contains("file")) << (las ? las->dump() : "") << viewer.errors();
  const auto csv = press(viewer, frame, "Profile CSV");
  ASSERT_TRUE(csv && csv->contains("file")) << (csv ? csv->dump() : "") << viewer.errors();
  EXPECT_EQ((*las)["points"], (*cut)["points"]);
  const std::string stem = (dir / (line ? "typed" : "pointrast-profile")).string();
  EXPECT_EQ((*png)["file"], stem + ".png");
  EXPECT_EQ((*las)["file"], stem + ".las");
  EXPECT_EQ((*csv)["file"], stem + ".csv");
  const Capture window = captureWindow(display, viewer.window());
  EXPECT_EQ(viewer.quit(), 0) << viewer.errors();

  cliProfile(input, drawn, kWidth, std::to_string(width) + "x" + std::to_string(height), dir);
  uint32_t w = 0, h = 0, cw = 0, ch = 0;
  const std::vector<uint32_t> mine = loadRgba((*png)["file"].get<std::string>(), w, h);
  const std::vector<uint32_t> expected = loadRgba(dir / "cli.png", cw, ch);
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(w, cw);
  EXPECT_EQ(h, ch);
  EXPECT_TRUE(mine == expected) << "the panel's picture differs from pointrast profile's";
  const std::vector<std::string> records = sortedRecords((*las)["file"].get<std::string>());
  EXPECT_EQ(records.size(), (*las)["points"].get<uint64_t>());
  EXPECT_TRUE(records == sortedRecords(dir / "cli.las")) << "the panel's LAS differs from profile --las";
  const std::vector<std::string> rows = sortedLines((*csv)["file"].get<std::string>());
  EXPECT_EQ(rows.size(), (*csv)["points"].get<uint64_t>() + 1); // a header line
  EXPECT_TRUE(rows == sortedLines(dir / "cli.csv")) << "the panel's CSV differs from profile --csv";

  // The Profile window shows the picture at its own size: its pixels are the picture's (opaque).
  ASSERT_EQ(window.rgba.size(), size_t(window.width) * window.height);
  const std::vector<float> r = (*frame)["panel_items"]["profile image"].get<std::vector<float>>();
  ASSERT_EQ(uint32_t(r[2]), width);
  ASSERT_EQ(uint32_t(r[3]), height);
  const uint32_t x0 = uint32_t(r[0]), y0 = uint32_t(r[1]);
  ASSERT_LE(x0 + width, window.width);
  ASSERT_LE(y0 + height, window.height);
  size_t differ = 0;
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x)
      differ += ((window.rgba[size_t(y0 + y) * window.width + x0 + x] ^ expected[size_t(y) * cw + x]) &
                 0xFFFFFFu) != 0;
  EXPECT_EQ(differ, 0u) << "pixels of the Profile window differ from the picture (" << (dir / "window.png")
                        << ")";
  if (differ) io::writePng(dir / "window.png", window.width, window.height, window.rgba.data());
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

TEST_F(ViewerProfile, LineDrawnOnAFileGivesTheProfileCommandsPictureAndExports) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  checkPanelProfile(xvfb_->display(), (dataDir() / "las" / "autzen_trim.las").string(), "las", nullptr);
}

TEST_F(ViewerProfile, LineTypedOnAFileGivesTheProfileCommandsPictureAndExports) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  checkPanelProfile(xvfb_->display(), (dataDir() / "las" / "autzen_trim.las").string(), "typed", kLine);
}

TEST_F(ViewerProfile, LineTypedOnAnOctreeGivesTheProfileCommandsPictureAndExports) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const std::filesystem::path octree = profileTempDir() / "autzen_octree";
  std::filesystem::remove_all(octree);
  const std::string build = "'" + pointrastBinary() + "' lod '" +
                            (dataDir() / "las" / "autzen_trim.las").string() + "' -o '" + octree.string() +
                            "' -q";
  ASSERT_EQ(std::system(build.c_str()), 0) << build;
  checkPanelProfile(xvfb_->display(), octree.string(), "octree", kLine);
  if (!HasFailure()) std::filesystem::remove_all(octree);
}

} // namespace
} // namespace pointrast::test
