// The page in Debian's chromium (headless, driven by tests/web/browser.mjs through playwright-core) against
// `pointrast serve` on lavapipe: what a user sees and does.
#include <gtest/gtest.h>

#include "image_compare.h"
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
