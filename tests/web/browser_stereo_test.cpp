// The page's Stereo controls in Debian's chromium (headless, tests/web/browser.mjs through playwright-core)
// against `pointrast serve` on lavapipe: ticking Stereo, typing an eye separation and ticking Cross-eyed
// change the canvas as render's
// --stereo and --stereo-layout cross-eyed do, both eyes side by side at half the canvas's width.
#include <string>

#include <gtest/gtest.h>

#include "image_compare.h"
#include "serve_harness.h"

namespace pointrast::test {
namespace {

// Runs a scenario of browser.mjs; its last line is the JSON result.
Json runBrowser(const std::string& scenario, const std::string& url, const std::filesystem::path& outdir,
                const Json& args) {
  const std::string dir = std::string(POINTRAST_SOURCE_DIR) + "/tests/web";
  const std::string command = "cd '" + dir + "' && node browser.mjs " + scenario + " '" + url + "' '" +
                              outdir.string() + "' '" + args.dump() + "' 2>&1";
  const std::string out = commandOutput(command);
  const size_t last = out.rfind('\n', out.size() >= 2 ? out.size() - 2 : 0);
  Json result = Json::parse(last == std::string::npos ? out : out.substr(last + 1), nullptr, false);
  if (!result.is_object()) ADD_FAILURE() << "browser.mjs " << scenario << " printed:\n" << out;
  if (result.is_object() && result.contains("failure")) ADD_FAILURE() << result["failure"].get<std::string>();
  return result.is_object() ? result : Json::object();
}

TEST(BrowserStereo, StereoControlsChangeTheCanvasAsRenderOptionsDo) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const std::string dir = std::string(POINTRAST_SOURCE_DIR) + "/tests/web";
  ASSERT_TRUE(std::filesystem::exists(dir + "/node_modules/playwright-core"))
      << "playwright-core is not installed: run scripts/web-test-setup.sh (npm ci in tests/web)";
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"))
      << "chromium is missing: run scripts/install-deps.sh";
  ServeProcess server(autzen() + " " + kAutzenCamera + " --method batch");
  ASSERT_TRUE(server.listening()) << server.stderrText();
  const auto out = scratchDir("browser_stereo");
  const Json steps = Json::array({
      {{"id", "stereo"}, {"check", true}, {"expect", "--method batch --stereo"}},
      {{"id", "ipd"}, {"value", 60}, {"expect", "--method batch --stereo --ipd 60"}},
      {{"id", "crossed"},
       {"check", true},
       {"expect", "--method batch --stereo --ipd 60 --stereo-layout cross-eyed"}},
  });
  Json r = runBrowser("settings", server.url(), out, {{"steps", steps}});
  ASSERT_TRUE(r.contains("shown"));
  EXPECT_EQ(r["errors"], Json::array());
  EXPECT_EQ(r["refusals"], Json::array());
  std::string previous = (out / "ref-start.png").string();
  commandOutput("'" + pointrastBinary() + "' render " + autzen() + " " + kAutzenCamera +
                " --method batch --width 640 --height 480 -q -o '" + previous + "'");
  for (size_t i = 0; i < steps.size(); ++i) {
    const std::string options = steps[i]["expect"];
    EXPECT_EQ(r["shown"][i], options);
    const std::string ref = (out / ("ref-" + std::to_string(i) + ".png")).string();
    commandOutput("'" + pointrastBinary() + "' render " + autzen() + " " + kAutzenCamera + " " + options +
                  " --width 320 --height 480 -q -o '" + ref + "'");
    const std::string shown = (out / ("step-" + std::to_string(i) + ".png")).string();
    ImageDifference own = comparePngs(shown, ref), before = comparePngs(shown, previous);
    ASSERT_TRUE(own.sameSize) << options;
    EXPECT_GE(own.psnr, kJpegPsnr) << options << ": mean abs " << own.meanAbs;
    EXPECT_LE(own.meanAbs, kJpegMeanAbs) << options;
    EXPECT_GT(before.meanAbs, own.meanAbs + 1.0) << options << ": the image did not change as render's does";
    previous = ref;
  }
  EXPECT_EQ(server.stop(), 0) << server.stderrText();
}

} // namespace
} // namespace pointrast::test
