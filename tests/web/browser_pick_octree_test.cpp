// A pick in the page (headless chromium through tests/web/browser.mjs) on an octree `pointrast serve`
// streams: the point the page receives and shows is the one `render --method lod --pick` finds at that
// pixel with the page's camera, with every attribute the octree keeps (PotreeConverter's octree of
// autzen_trim: GPS time, number of returns, scan angle rank, user data).
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "serve_harness.h"

namespace pointrast::test {
namespace {

const char* const kOctree = "potree/autzen_trim_default";
// Every node drawn whatever its size on screen, by serve and render alike.
const char* const kLod = " --min-node-px 0";

std::string octree() {
  return (dataDir() / kOctree).string();
}

// The page's camera as render options, every digit kept.
std::string cameraOptions(const Json& state) {
  const Json& c = state["camera"];
  char text[512];
  std::snprintf(text, sizeof text,
                "--eye %.17g,%.17g,%.17g --target %.17g,%.17g,%.17g --up %.17g,%.17g,%.17g --fov %.17g",
                c["eye"][0].get<double>(), c["eye"][1].get<double>(), c["eye"][2].get<double>(),
                c["target"][0].get<double>(), c["target"][1].get<double>(), c["target"][2].get<double>(),
                c["up"][0].get<double>(), c["up"][1].get<double>(), c["up"][2].get<double>(),
                c["fov"].get<double>());
  return text;
}

Json renderPick(const Json& state, const Json& pixel, const std::filesystem::path& dir) {
  const std::string out =
      commandOutput("'" + pointrastBinary() + "' render '" + octree() + "' --method lod" + kLod + " " +
                    cameraOptions(state) + " --width 640 --height 480 -q --json --pick " +
                    std::to_string(pixel[0].get<int>()) + "," + std::to_string(pixel[1].get<int>()) +
                    " -o '" + (dir / "pick.png").string() + "' 2>&1");
  const Json j = Json::parse(out.substr(std::min(out.find('{'), out.size())), nullptr, false);
  if (!j.is_object() || !j.contains("pick")) {
    ADD_FAILURE() << "render --pick printed:\n" << out;
    return Json::object();
  }
  return j["pick"];
}

TEST(BrowserPickOctree, APickShowsEveryAttributeRenderPicksOnTheOctree) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default/metadata.json");
  const std::string dir = std::string(POINTRAST_SOURCE_DIR) + "/tests/web";
  if (!std::filesystem::exists(dir + "/node_modules/playwright-core"))
    FAIL() << "playwright-core is not installed: run scripts/web-test-setup.sh (npm ci in tests/web)";
  ServeProcess server("'" + octree() + "' " + kAutzenCamera + kLod);
  ASSERT_TRUE(server.listening()) << server.stderrText();
  const auto scratch = scratchDir("browser_pick_octree");
  const Json pixels = {{450, 300}, {430, 260}}; // right of the panel (the left 390 pixels), on points
  Json steps = Json::array();
  for (const Json& p : pixels)
    steps.push_back({{"tool", "pick"}, {"pixel", p}});
  const Json r = browser("tools", server.url(), scratch, {{"steps", steps}});
  ASSERT_EQ(r["results"].size(), 2u) << r.dump();
  EXPECT_EQ(r["errors"], Json::array());
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Json& shown = r["results"][i];
    const Json& at = shown["pick"]["pixel"];
    ASSERT_TRUE(at.is_array()) << shown.dump();
    const Json expected = renderPick(r["shown"]["state"], at, scratch);
    const Json& p = expected["point"];
    ASSERT_TRUE(p.is_object()) << "the test's pixel shows no point: " << expected.dump();
    for (const char* key : {"node", "gps_time", "number_of_returns", "scan_angle", "user_data"})
      EXPECT_TRUE(p.contains(key)) << key << " missing from " << p.dump();
    Json page = shown["pick"];
    page.erase("world");
    EXPECT_EQ(page, expected) << "page " << shown["pick"].dump() << "\nrender " << expected.dump();
    // The panel shows them.
    const std::string text = shown["text"];
    for (const auto& [label, key] : {std::pair{"returns ", "number_of_returns"},
                                     {"scan angle ", "scan_angle"},
                                     {"user data ", "user_data"},
                                     {"node ", "node"}}) {
      const std::string value = p[key].is_string() ? p[key].get<std::string>() : p[key].dump();
      EXPECT_NE(text.find(label + value), std::string::npos) << label << value << " not in:\n" << text;
    }
    EXPECT_NE(text.find("GPS time "), std::string::npos) << text;
  }
  EXPECT_EQ(server.stop(), 0) << server.stderrText();
  const auto exit = server.exitEvent();
  ASSERT_TRUE(exit);
  EXPECT_EQ((*exit)["validation_errors"], 0);
}

} // namespace
} // namespace pointrast::test
