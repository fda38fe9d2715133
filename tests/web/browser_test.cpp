// The page in Debian's chromium (headless, driven by tests/web/browser.mjs through playwright-core) against
// `pointrast serve` on lavapipe: what a user sees and does.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "image_compare.h"
#include "las_records.h"
#include "serve_harness.h"
#include "view/navigation.h"

namespace pointrast::test {
namespace {

// Runs a scenario of browser.mjs; its last line is the JSON result.
Json browser(const std::string& scenario, const std::string& url, const std::filesystem::path& outdir,
             const Json& args = Json::object()) {
  std::string dir = std::string(POINTRAST_SOURCE_DIR) + "/tests/web";
  std::string command = "cd '" + dir + "' && node browser.mjs " + scenario + " '" + url + "' '" +
                        outdir.string() + "' '" + args.dump() + "' 2>&1";
  std::string out = commandOutput(command);
  size_t last = out.rfind('\n', out.size() >= 2 ? out.size() - 2 : 0);
  Json result = Json::parse(last == std::string::npos ? out : out.substr(last + 1), nullptr, false);
  if (!result.is_object()) ADD_FAILURE() << "browser.mjs " << scenario << " printed:\n" << out;
  if (result.is_object() && result.contains("failure")) ADD_FAILURE() << result["failure"].get<std::string>();
  return result.is_object() ? result : Json::object();
}

class Browser : public ::testing::Test {
protected:
  void SetUp() override {
    std::string dir = std::string(POINTRAST_SOURCE_DIR) + "/tests/web";
    if (!std::filesystem::exists(dir + "/node_modules/playwright-core"))
      FAIL() << "playwright-core is not installed: run scripts/web-test-setup.sh (npm ci in tests/web)";
    if (!std::filesystem::exists("/usr/bin/chromium"))
      FAIL() << "chromium is missing: run scripts/install-deps.sh";
  }
  void expectCleanExit(ServeProcess& server) {
    EXPECT_EQ(server.stop(), 0) << server.stderrText();
    auto exit = server.exitEvent();
    ASSERT_TRUE(exit);
    EXPECT_EQ((*exit)["validation_errors"], 0);
  }
};

Camera cameraOf(const Json& state) {
  Camera c;
  auto v = [](const Json& a) {
    return glm::dvec3(a[0].get<double>(), a[1].get<double>(), a[2].get<double>());
  };
  c.eye = v(state["camera"]["eye"]);
  c.target = v(state["camera"]["target"]);
  c.up = v(state["camera"]["up"]);
  c.fovY = state["camera"]["fov"];
  return c;
}

void expectNear(const glm::dvec3& a, const glm::dvec3& b, double tolerance, const char* what) {
  EXPECT_LE(glm::length(a - b), tolerance) << what << ": (" << a.x << ", " << a.y << ", " << a.z << ") vs ("
                                           << b.x << ", " << b.y << ", " << b.z << ")";
}

TEST_F(Browser, ThePageShowsTheFrameRenderShowsWithinJpegTolerance) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen() + " " + kAutzenCamera);
  ASSERT_TRUE(server.listening()) << server.stderrText();
  auto dir = scratchDir("browser_frame");
  Json r = browser("frame", server.url(), dir);
  ASSERT_TRUE(r.contains("frame"));
  EXPECT_EQ(r["status"], 200);
  EXPECT_EQ(r["errors"], Json::array());
  EXPECT_EQ(r["canvas"], Json::array({640, 480}));
  EXPECT_EQ(r["frame"]["full"], true);
  EXPECT_EQ(r["frame"]["width"], 640);
  std::string ref = (dir / "ref.png").string();
  commandOutput("'" + pointrastBinary() + "' render '" + autzen() + "' " + kAutzenCamera +
                " --width 640 --height 480 -q -o '" + ref + "'");
  ImageDifference d = comparePngs((dir / "canvas.png").string(), ref);
  ASSERT_TRUE(d.sameSize);
  EXPECT_GE(d.psnr, kJpegPsnr) << "mean abs " << d.meanAbs;
  EXPECT_LE(d.meanAbs, kJpegMeanAbs);
  std::printf("canvas vs render: PSNR %.2f dB, mean absolute difference %.3f / 255\n", d.psnr, d.meanAbs);
  expectCleanExit(server);
}

// The page sends positions; the session core turns them into the camera. A drag in chromium must move
// the camera exactly as Navigation computes for the same pixels (the desktop viewer's tests check the
// same core against an X11 drag).
TEST_F(Browser, ADragOrbitsByWhatTheSessionCoreComputes) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen() + " " + kAutzenCamera);
  ASSERT_TRUE(server.listening()) << server.stderrText();
  const glm::dvec2 from(450, 240), to(560, 300); // right of the panel
  Json r = browser("drag", server.url(), scratchDir("browser_drag"),
                   {{"from", {from.x, from.y}}, {"to", {to.x, to.y}}});
  ASSERT_TRUE(r.contains("after"));
  EXPECT_EQ(r["errors"], Json::array());
  Camera before = cameraOf(r["before"]["state"]), after = cameraOf(r["after"]["state"]);
  view::Viewport viewport{r["after"]["state"]["viewport"][0], r["after"]["state"]["viewport"][1]};
  ASSERT_EQ(viewport, (view::Viewport{640, 480}));
  Bounds bounds;
  view::Navigation navigation(bounds, before);
  navigation.beginDrag(view::DragMode::Orbit, from);
  navigation.drag(to, viewport);
  double scale = glm::length(before.eye - before.target);
  expectNear(after.eye, navigation.camera().eye, 1e-9 * scale, "eye");
  expectNear(after.target, navigation.camera().target, 1e-9 * scale, "target");
  EXPECT_GT(glm::length(after.eye - before.eye), 0.1 * scale) << "the drag did not move the camera";
  expectCleanExit(server);
}

TEST_F(Browser, AResizeChangesTheFrameSize) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen());
  ASSERT_TRUE(server.listening()) << server.stderrText();
  Json r = browser("resize", server.url(), scratchDir("browser_resize"), {{"width", 800}, {"height", 500}});
  ASSERT_TRUE(r.contains("after"));
  EXPECT_EQ(r["before"]["frame"]["width"], 640);
  EXPECT_EQ(r["after"]["frame"]["width"], 800);
  EXPECT_EQ(r["after"]["frame"]["height"], 500);
  EXPECT_EQ(r["after"]["state"]["viewport"], Json::array({800, 500}));
  EXPECT_EQ(r["canvas"], Json::array({800, 500}));
  expectCleanExit(server);
}

TEST_F(Browser, TwoTabsHaveIndependentCameras) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen() + " " + kAutzenCamera);
  ASSERT_TRUE(server.listening()) << server.stderrText();
  Json r =
      browser("two", server.url(), scratchDir("browser_two"), {{"from", {450, 240}}, {"to", {600, 200}}});
  ASSERT_TRUE(r.contains("b1"));
  EXPECT_EQ(r["errors"], Json::array());
  Camera a0 = cameraOf(r["a0"]["state"]), a1 = cameraOf(r["a1"]["state"]);
  Camera b0 = cameraOf(r["b0"]["state"]), b1 = cameraOf(r["b1"]["state"]);
  EXPECT_GT(glm::length(a1.eye - a0.eye), 1.0) << "the dragged tab's camera did not move";
  EXPECT_EQ(b1.eye, b0.eye) << "the other tab's camera moved";
  EXPECT_EQ(r["b1"]["frames"], r["b0"]["frames"]) << "the other tab got frames it did not cause";
  expectCleanExit(server);
}

// Each panel control changes the streamed image as `render` with its option does: the frame after each
// step matches render with that step's options (within JPEG's tolerance), and is farther from the image
// before the step than from its own reference, so a control that changed nothing would fail.
TEST_F(Browser, PanelControlsChangeTheImageAsRenderOptionsDo) {
  ServeProcess server(autzen() + " " + kAutzenCamera);
  ASSERT_TRUE(server.listening()) << server.stderrText();
  auto dir = scratchDir("browser_settings");
  const Json steps = Json::array({
      {{"id", "color"}, {"value", "intensity"}, {"expect", "--color intensity"}},
      {{"id", "pointSize"}, {"value", 3}, {"expect", "--color intensity --point-size 3"}},
      {{"id", "edl"}, {"check", true}, {"expect", "--color intensity --point-size 3 --edl"}},
      {{"id", "dilate"}, {"value", 2}, {"expect", "--color intensity --point-size 3 --dilate 2 --edl"}},
      {{"id", "color"},
       {"value", "classification"},
       {"expect", "--color classification --point-size 3 --dilate 2 --edl"}},
  });
  Json r = browser("settings", server.url(), dir, {{"steps", steps}});
  ASSERT_TRUE(r.contains("shown"));
  EXPECT_EQ(r["errors"], Json::array());
  EXPECT_EQ(r["refusals"], Json::array());
  std::string previous = (dir / "ref-start.png").string();
  commandOutput("'" + pointrastBinary() + "' render '" + autzen() + "' " + kAutzenCamera +
                " --width 640 --height 480 -q -o '" + previous + "'");
  for (size_t i = 0; i < steps.size(); ++i) {
    const std::string options = steps[i]["expect"];
    EXPECT_EQ(r["shown"][i], options);
    std::string ref = (dir / ("ref-" + std::to_string(i) + ".png")).string();
    commandOutput("'" + pointrastBinary() + "' render '" + autzen() + "' " + kAutzenCamera + " " + options +
                  " --width 640 --height 480 -q -o '" + ref + "'");
    std::string shown = (dir / ("step-" + std::to_string(i) + ".png")).string();
    ImageDifference own = comparePngs(shown, ref), before = comparePngs(shown, previous);
    ASSERT_TRUE(own.sameSize) << options;
    EXPECT_GE(own.psnr, kJpegPsnr) << options << ": mean abs " << own.meanAbs;
    EXPECT_LE(own.meanAbs, kJpegMeanAbs) << options;
    EXPECT_GT(before.meanAbs, own.meanAbs + 1.0) << options << ": the image did not change as render's does";
    std::printf("%s: PSNR %.2f dB to render, mean abs %.3f (%.3f to the image before)\n", options.c_str(),
                own.psnr, own.meanAbs, before.meanAbs);
    previous = ref;
  }
  expectCleanExit(server);
}

// The camera of a page's state as render options, every digit kept.
std::string cameraOptions(const Camera& c) {
  char text[512];
  std::snprintf(text, sizeof text, "--eye %.17g,%.17g,%.17g --target %.17g,%.17g,%.17g --up %.17g,%.17g,%.17g --fov %.17g",
                c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z, c.fovY);
  return text;
}

// render --pick at a pixel of a 640x480 image with the page's camera: the "pick" object of its JSON.
Json renderPick(const Camera& camera, const Json& pixel, const std::filesystem::path& dir) {
  std::string out = commandOutput("'" + pointrastBinary() + "' render '" + autzen() + "' " + cameraOptions(camera) +
                                  " --width 640 --height 480 -q --json --pick " + std::to_string(pixel[0].get<int>()) +
                                  "," + std::to_string(pixel[1].get<int>()) + " -o '" + (dir / "pick.png").string() +
                                  "' 2>&1");
  Json j = Json::parse(out.substr(out.find('{')), nullptr, false);
  if (!j.is_object() || !j.contains("pick")) {
    ADD_FAILURE() << "render --pick printed:\n" << out;
    return Json::object();
  }
  return j["pick"];
}

glm::dvec3 pointOf(const Json& point) {
  return {point["x"].get<double>(), point["y"].get<double>(), point["z"].get<double>()};
}

TEST_F(Browser, APickShowsThePointRenderPicksAtThatPixel) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen() + " " + kAutzenCamera);
  ASSERT_TRUE(server.listening()) << server.stderrText();
  auto dir = scratchDir("browser_pick");
  const Json pixels = {{450, 300}, {430, 260}}; // right of the panel (the left 390 pixels), on points
  Json steps = Json::array();
  for (const Json& p : pixels)
    steps.push_back({{"tool", "pick"}, {"pixel", p}});
  Json r = browser("tools", server.url(), dir, {{"steps", steps}});
  ASSERT_EQ(r["results"].size(), 2u);
  EXPECT_EQ(r["errors"], Json::array());
  const Camera camera = cameraOf(r["shown"]["state"]);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Json& shown = r["results"][i];
    // The nearest pixel within the pick radius (2) that shows a point: render --pick there.
    const Json& at = shown["pick"]["pixel"];
    ASSERT_TRUE(at.is_array()) << shown.dump();
    EXPECT_LE(std::abs(at[0].get<int>() - pixels[i][0].get<int>()), 2);
    EXPECT_LE(std::abs(at[1].get<int>() - pixels[i][1].get<int>()), 2);
    const Json expected = renderPick(camera, at, dir);
    ASSERT_TRUE(expected["point"].is_object()) << "the test's pixel shows no point: " << expected.dump();
    Json page = shown["pick"];
    page.erase("world");
    EXPECT_EQ(page, expected) << "page " << shown["pick"].dump() << "\nrender " << expected.dump();
    // The panel shows the attributes.
    const std::string text = shown["text"];
    EXPECT_NE(text.find("intensity " + std::to_string(expected["point"]["intensity"].get<int>())), std::string::npos)
        << text;
    EXPECT_NE(text.find("class " + std::to_string(expected["point"]["classification"].get<int>())), std::string::npos)
        << text;
  }
  // Ctrl+click picks with the tool left at navigating, and does not move the camera.
  Json c = browser("tools", server.url(), dir, {{"steps", Json::array({steps[0]})}, {"ctrl", true}});
  ASSERT_EQ(c["results"].size(), 1u);
  Json page = c["results"][0]["pick"];
  page.erase("world");
  EXPECT_EQ(page, renderPick(cameraOf(c["after"]["state"]), page["pixel"], dir));
  expectNear(cameraOf(c["after"]["state"]).eye, camera.eye, 1e-9, "eye after a Ctrl+click");
  expectCleanExit(server);
}

TEST_F(Browser, ADistanceBetweenTwoClicksIsTheDistanceOfThePickedPoints) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen() + " " + kAutzenCamera);
  ASSERT_TRUE(server.listening()) << server.stderrText();
  auto dir = scratchDir("browser_distance");
  const Json pixels = {{410, 250}, {460, 280}};
  Json steps = Json::array();
  for (const Json& p : pixels)
    steps.push_back({{"tool", "distance"}, {"pixel", p}});
  Json r = browser("tools", server.url(), dir, {{"steps", steps}, {"download", true}});
  ASSERT_EQ(r["results"].size(), 2u);
  EXPECT_EQ(r["errors"], Json::array());
  const Camera camera = cameraOf(r["shown"]["state"]);
  const Json a = renderPick(camera, r["results"][0]["pick"]["pixel"], dir),
             b = renderPick(camera, r["results"][1]["pick"]["pixel"], dir);
  ASSERT_TRUE(a["point"].is_object() && b["point"].is_object());
  const double expected = glm::length(pointOf(a["point"]) - pointOf(b["point"]));
  ASSERT_GT(expected, 1.0);
  const Json& list = r["results"][1]["measurements"];
  ASSERT_EQ(list.size(), 1u) << list.dump();
  ASSERT_TRUE(list[0].contains("value")) << list.dump();
  EXPECT_EQ(list[0]["type"], "distance");
  EXPECT_NEAR(list[0]["value"].get<double>(), expected, 1e-9 * expected);
  char shownText[64];
  std::snprintf(shownText, sizeof shownText, "distance %.2f", expected);
  EXPECT_NE(r["results"][1]["listText"].get<std::string>().find(shownText), std::string::npos)
      << r["results"][1]["listText"];
  // The downloaded annotations file holds the two picked points.
  ASSERT_TRUE(r["annotations"].is_string());
  std::ifstream in(r["annotations"].get<std::string>());
  Json file = Json::parse(in, nullptr, false);
  ASSERT_TRUE(file.is_object() && file.contains("annotations")) << file.dump();
  ASSERT_EQ(file["annotations"].size(), 1u);
  EXPECT_EQ(file["annotations"][0]["type"], "distance");
  expectNear(pointOf({{"x", file["annotations"][0]["points"][0][0]}, {"y", file["annotations"][0]["points"][0][1]},
                      {"z", file["annotations"][0]["points"][0][2]}}),
             pointOf(a["point"]), 1e-9, "first vertex");
  expectCleanExit(server);
}

TEST_F(Browser, DraggingAVertexMovesItToThePointUnderTheRelease) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen() + " " + kAutzenCamera);
  ASSERT_TRUE(server.listening()) << server.stderrText();
  auto dir = scratchDir("browser_move");
  const Json steps = {{{"tool", "distance"}, {"pixel", {410, 250}}},
                      {{"tool", "distance"}, {"pixel", {460, 280}}},
                      {{"tool", "pick"}, {"drag", {{410, 250}, {440, 230}}}}};
  Json r = browser("tools", server.url(), dir, {{"steps", steps}});
  ASSERT_EQ(r["results"].size(), 3u) << r.dump();
  EXPECT_EQ(r["errors"], Json::array());
  const Camera camera = cameraOf(r["shown"]["state"]);
  const Json& moved = r["results"][2]["moved"];
  ASSERT_TRUE(moved["moved"].get<bool>()) << moved.dump();
  EXPECT_EQ(moved["index"], 0);
  EXPECT_EQ(moved["vertex"], 0);
  // The vertex is now the point render --pick finds where the drag ended.
  const Json& at = moved["pick"]["pixel"];
  EXPECT_LE(std::abs(at[0].get<int>() - 440), 2);
  EXPECT_LE(std::abs(at[1].get<int>() - 230), 2);
  const Json expected = renderPick(camera, at, dir);
  ASSERT_TRUE(expected["point"].is_object()) << expected.dump();
  const Json& list = r["results"][2]["measurements"];
  ASSERT_EQ(list.size(), 1u) << list.dump();
  const Json& p0 = list[0]["points"][0];
  const glm::dvec3 first(p0[0].get<double>(), p0[1].get<double>(), p0[2].get<double>());
  expectNear(first, pointOf(expected["point"]), 1e-9, "moved vertex");
  const Json& p1 = list[0]["points"][1];
  const glm::dvec3 second(p1[0].get<double>(), p1[1].get<double>(), p1[2].get<double>());
  expectNear(second, pointOf(r["results"][1]["pick"]["point"]), 1e-9, "the other vertex stays");
  EXPECT_NEAR(list[0]["value"].get<double>(), glm::length(first - second),
              1e-9 * glm::length(first - second));
  expectCleanExit(server);
}

glm::dvec3 recordPosition(const LasRecords& las, const std::string& record) {
  int32_t v[3];
  std::memcpy(v, record.data(), 12);
  return glm::dvec3(v[0], v[1], v[2]) * las.scale + las.offset;
}

TEST_F(Browser, ExportDownloadsThePointsInsideTheClipBoxAsLas) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  // The server's temporary files go to a folder of this test's own, so that what tests running beside
  // it export does not show in the check below.
  const auto tmp = scratchDir("browser_export_tmp");
  ServeProcess server(autzen() + " " + kAutzenCamera, "env TMPDIR='" + tmp.string() + "'");
  ASSERT_TRUE(server.listening()) << server.stderrText();
  auto dir = scratchDir("browser_export");
  const glm::dvec3 lo(636400, 849000, 300), hi(636800, 849400, 600);
  char box[200];
  std::snprintf(box, sizeof box, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
  Json r = browser("export", server.url(), dir, {{"box", box}, {"mode", "inside"}});
  EXPECT_EQ(r["errors"], Json::array());
  ASSERT_TRUE(r["file"].is_string()) << r.dump();
  // The test's own selection from the input: the records whose position lies in the closed box.
  const LasRecords input = readLasRecords(autzen());
  std::vector<std::string> expected;
  for (const std::string& record : input.records) {
    const glm::dvec3 p = recordPosition(input, record);
    if (glm::all(glm::greaterThanEqual(p, lo)) && glm::all(glm::lessThanEqual(p, hi))) expected.push_back(record);
  }
  ASSERT_GT(expected.size(), 100u);
  ASSERT_LT(expected.size(), input.records.size());
  const LasRecords exported = readLasRecords(r["file"].get<std::string>());
  EXPECT_EQ(r["exported"]["points"], expected.size());
  ASSERT_EQ(exported.records.size(), expected.size());
  std::vector<std::string> got = exported.records;
  std::sort(got.begin(), got.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_TRUE(got == expected) << "the exported records are not the input's records inside the box";
  // No temporary file is left behind.
  EXPECT_EQ(commandOutput("ls -d '" + tmp.string() + "'/pointrast-export-* 2>/dev/null"), "");
  expectCleanExit(server);
}

TEST_F(Browser, ExportSaysWhyAGeneratedSceneCannotBeExported) {
  ServeProcess server("terrain --points 20000");
  ASSERT_TRUE(server.listening()) << server.stderrText();
  Json r = browser("export", server.url(), scratchDir("browser_export_refused"), Json::object());
  ASSERT_TRUE(r["exported"]["error"].is_string()) << r.dump();
  const std::string why = r["exported"]["error"];
  EXPECT_NE(why.find("generated scene"), std::string::npos) << why;
  EXPECT_EQ(r["shown"], why);
  EXPECT_TRUE(r["file"].is_null());
  expectCleanExit(server);
}

// 127.0.0.2 is a loopback address that counts as non-local for the token rule.
TEST_F(Browser, AWrongOrMissingTokenIsRefusedInTheBrowser) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen() + " --bind 127.0.0.2");
  ASSERT_TRUE(server.listening()) << server.stderrText();
  std::string url = server.url();
  ASSERT_NE(url.find("?token="), std::string::npos);
  Json r =
      browser("token", url, scratchDir("browser_token"), {{"token", url.substr(url.find("?token=") + 7)}});
  EXPECT_EQ(r["none"]["status"], 403);
  EXPECT_EQ(r["wrong"]["status"], 403);
  EXPECT_EQ(r["right"]["status"], 200);
  EXPECT_EQ(r["right"]["shown"]["frame"]["full"], true);
  EXPECT_EQ(r["wsNone"]["opened"], false);
  EXPECT_EQ(r["wsWrong"]["opened"], false);
  EXPECT_EQ(r["wsRight"]["opened"], true);
  // Refused by the server, not kept from it by the browser.
  size_t socketsRefused = 0;
  for (const Json& e : server.events())
    socketsRefused += e.value("event", "") == "refused" && e.value("websocket", false) ? 1 : 0;
  EXPECT_EQ(socketsRefused, 2u);
  expectCleanExit(server);
}

} // namespace
} // namespace pointrast::test
