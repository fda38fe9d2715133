// `pointrast serve` on octrees (lavapipe, validation layer on): a Potree 2.0 folder and a COPC file open
// with lod by default, the page's frames keep coming while nodes stream in, and the full frame once the
// view has converged equals `render --method lod` with the same camera within JPEG tolerance.
#include <gtest/gtest.h>

#include "image_compare.h"
#include "serve_harness.h"
#include "view/web/jpeg.h"
#include "view/web/protocol.h"
#include "ws_client.h"

namespace pointrast::test {
namespace {

using wsclient::Client;

// Opens a client of `port` at w x h and reads frames (acknowledging each) until a full frame whose state
// says the level of detail converged; that frame's JPEG, or nothing after `seconds`.
// The first full frame drawn once the view converged, after `settings` (a "settings" message, as the
// page's panel sends) when given: then only a frame whose state shows `options` (the settings as render
// options) counts.
std::optional<std::vector<uint8_t>> convergedFrame(uint16_t port, uint32_t w, uint32_t h, Json& state,
                                                   double seconds = 120, const Json& settings = nullptr,
                                                   const std::string& options = "") {
  Client ws;
  if (!ws.connect("127.0.0.1", port, "/ws")) return std::nullopt;
  ws.sendText(Json{{"t", "resize"}, {"w", w}, {"h", h}}.dump());
  if (!settings.is_null()) ws.sendText(settings.dump());
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  bool converged = false;
  while (std::chrono::steady_clock::now() < deadline) {
    auto m = ws.receive(std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count());
    if (!m) return std::nullopt;
    if (m->opcode == 1) {
      Json j = Json::parse(m->text(), nullptr, false);
      if (j.is_object() && j.value("t", "") == "state") {
        state = j;
        converged = j.contains("stats") && j["stats"].contains("lod") &&
                    j["stats"]["lod"].value("converged", false) &&
                    (settings.is_null() || (j.contains("settings") && j["settings"].is_object() &&
                                            j["settings"].value("options", "") == options));
      }
      continue;
    }
    if (m->opcode != 2) continue;
    view::web::FrameHeader header = view::web::readFrameHeader(m->data.data());
    if (header.magic != view::web::kFrameMagic) continue;
    ws.sendText(Json{{"t", "ack"}, {"frame", header.frame}}.dump());
    // A frame's state comes before its image.
    if (converged && (header.flags & view::web::kFrameFull))
      return std::vector<uint8_t>(m->data.begin() + view::web::kFrameHeaderBytes, m->data.end());
  }
  return std::nullopt;
}

void expectConvergedFrameEqualsRender(const std::string& input) {
  SCOPED_TRACE(input);
  ServeProcess server("'" + input + "' " + kAutzenCamera);
  ASSERT_TRUE(server.listening()) << server.stderrText();
  Json state;
  auto jpeg = convergedFrame(server.port(), 320, 240, state);
  ASSERT_TRUE(jpeg) << server.stderrText();
  EXPECT_GT(state["stats"]["lod"]["pointsDrawn"].get<uint64_t>(), 0u) << state.dump();
  uint32_t w = 0, h = 0;
  std::vector<uint32_t> shown;
  ASSERT_TRUE(view::web::decodeJpeg(*jpeg, w, h, shown));
  ASSERT_EQ(w, 320u);
  ASSERT_EQ(h, 240u);
  const std::string ref = (scratchDir("lod_frame") / "ref.png").string();
  commandOutput("'" + pointrastBinary() + "' render '" + input + "' --method lod " + kAutzenCamera +
                " --width 320 --height 240 -q -o '" + ref + "'");
  ImageDifference d = compareWithPng(shown, w, h, ref);
  EXPECT_GE(d.psnr, kJpegPsnr) << "mean abs " << d.meanAbs;
  EXPECT_LE(d.meanAbs, kJpegMeanAbs);
  EXPECT_EQ(server.stop(), 0) << server.stderrText();
}

TEST(ServeLod, PotreeOctreeOpensWithLodAndItsConvergedFrameEqualsRender) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default");
  expectConvergedFrameEqualsRender((dataDir() / "potree" / "autzen_trim_default").string());
}

TEST(ServeLod, PotreeBrotliOctreeOpensWithLodAndItsConvergedFrameEqualsRender) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_brotli");
  expectConvergedFrameEqualsRender((dataDir() / "potree" / "autzen_trim_brotli").string());
}

// The panel's level-of-detail controls: a point budget and a minimum node size sent as the page sends them
// give the frame `render --method lod` draws with those options, and a different one than before.
TEST(ServeLod, PointBudgetAndMinNodeSizeFromThePanelEqualRender) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default");
  const std::string input = (dataDir() / "potree" / "autzen_trim_default").string();
  ServeProcess server("'" + input + "' " + kAutzenCamera);
  ASSERT_TRUE(server.listening()) << server.stderrText();
  const auto dir = scratchDir("lod_panel");
  auto render = [&](const std::string& options, const std::string& name) {
    const std::string png = (dir / name).string();
    commandOutput("'" + pointrastBinary() + "' render '" + input + "' --method lod " + kAutzenCamera + " " +
                  options + " --width 320 --height 240 -q -o '" + png + "'");
    return png;
  };
  const std::string unchanged = render("", "default.png");
  const struct {
    Json settings;
    std::string options;
  } steps[] = {{{{"t", "settings"}, {"pointBudget", 20000}}, "--point-budget 20000"},
               {{{"t", "settings"}, {"minNodePx", 400}}, "--min-node-px 400"}};
  for (const auto& step : steps) {
    SCOPED_TRACE(step.options);
    Json state;
    // The state names the method too: an octree opens with lod, which is not the settings' default.
    auto jpeg = convergedFrame(server.port(), 320, 240, state, 60, step.settings, "--method lod " + step.options);
    ASSERT_TRUE(jpeg) << server.stderrText() << "\nlast state: " << state.dump();
    uint32_t w = 0, h = 0;
    std::vector<uint32_t> shown;
    ASSERT_TRUE(view::web::decodeJpeg(*jpeg, w, h, shown));
    ASSERT_EQ(w, 320u);
    const std::string ref = render(step.options, "ref.png");
    ImageDifference own = compareWithPng(shown, w, h, ref), before = compareWithPng(shown, w, h, unchanged);
    EXPECT_GE(own.psnr, kJpegPsnr) << "mean abs " << own.meanAbs;
    EXPECT_LE(own.meanAbs, kJpegMeanAbs);
    EXPECT_GT(before.meanAbs, own.meanAbs + 1.0) << "the frame did not change as render's does";
  }
  EXPECT_EQ(server.stop(), 0) << server.stderrText();
}

} // namespace
} // namespace pointrast::test
