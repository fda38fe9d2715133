// `pointrast serve --stereo` on an octree (lavapipe, validation layer on): the page's converged frame shows
// both eyes side by side, each half the canvas, as `render --method lod --stereo` draws them at an eye's size
// (within JPEG tolerance); the page's Foveated and Stereo controls, sent as the page sends them, change the
// frame as render's options do.
#include <gtest/gtest.h>

#include "image_compare.h"
#include "serve_harness.h"
#include "view/web/jpeg.h"
#include "view/web/protocol.h"
#include "ws_client.h"

namespace pointrast::test {
namespace {

using wsclient::Client;

constexpr uint32_t kWidth = 320, kHeight = 240;

// Reads frames of an open client (acknowledging each) until a full frame whose state says the level of
// detail converged and shows `options` (the settings as render options); that frame's JPEG, or nothing
// after `seconds`.
std::optional<std::vector<uint8_t>> convergedFrame(Client& ws, const std::string& options, Json& state,
                                                   double seconds = 90) {
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
                    j["stats"]["lod"].value("converged", false) && j.contains("settings") &&
                    j["settings"].is_object() && j["settings"].value("options", "") == options;
      }
      continue;
    }
    if (m->opcode != 2) continue;
    view::web::FrameHeader header = view::web::readFrameHeader(m->data.data());
    if (header.magic != view::web::kFrameMagic) continue;
    ws.sendText(Json{{"t", "ack"}, {"frame", header.frame}}.dump());
    if (converged && (header.flags & view::web::kFrameFull))
      return std::vector<uint8_t>(m->data.begin() + view::web::kFrameHeaderBytes, m->data.end());
  }
  return std::nullopt;
}

TEST(ServeStereo, StereoAndFoveatedFramesEqualRenderWithTheOptions) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default");
  const std::string input = (dataDir() / "potree" / "autzen_trim_default").string();
  ServeProcess server("'" + input + "' " + kAutzenCamera + " --min-node-px 30 --stereo");
  ASSERT_TRUE(server.listening()) << server.stderrText();
  const auto dir = scratchDir("serve_stereo");
  // render at an eye's size in stereo (the side-by-side image is the canvas's size), else the canvas's.
  auto render = [&](const std::string& options, const std::string& name) {
    const std::string png = (dir / name).string();
    const bool stereo = options.find("--stereo") != std::string::npos;
    commandOutput("'" + pointrastBinary() + "' render '" + input + "' " + kAutzenCamera + " " + options +
                  " --width " + std::to_string(stereo ? kWidth / 2 : kWidth) + " --height " +
                  std::to_string(kHeight) + " -q -o '" + png + "'");
    return png;
  };
  Client ws;
  ASSERT_TRUE(ws.connect("127.0.0.1", server.port(), "/ws"));
  ws.sendText(Json{{"t", "resize"}, {"w", kWidth}, {"h", kHeight}}.dump());
  const struct {
    Json settings; // null: none, the options serve started with
    std::string options;
  } steps[] = {{nullptr, "--method lod --min-node-px 30 --stereo"},
               {{{"t", "settings"}, {"foveated", true}, {"foveaRadius", 0}, {"foveaPeriphery", 20}},
                "--method lod --min-node-px 30 --stereo --foveated --fovea-radius 0 --fovea-periphery 20"},
               {{{"t", "settings"}, {"stereo", false}},
                "--method lod --min-node-px 30 --foveated --fovea-radius 0 --fovea-periphery 20"}};
  std::string before;
  for (const auto& step : steps) {
    SCOPED_TRACE(step.options);
    if (!step.settings.is_null()) ws.sendText(step.settings.dump());
    Json state;
    auto jpeg = convergedFrame(ws, step.options, state);
    ASSERT_TRUE(jpeg) << server.stderrText() << "\nlast state: " << state.dump();
    uint32_t w = 0, h = 0;
    std::vector<uint32_t> shown;
    ASSERT_TRUE(view::web::decodeJpeg(*jpeg, w, h, shown));
    ASSERT_EQ(w, kWidth);
    ASSERT_EQ(h, kHeight);
    const std::string ref = render(step.options, "ref_" + std::to_string(&step - steps) + ".png");
    ImageDifference own = compareWithPng(shown, w, h, ref);
    EXPECT_GE(own.psnr, kJpegPsnr) << "mean abs " << own.meanAbs;
    EXPECT_LE(own.meanAbs, kJpegMeanAbs);
    if (!before.empty()) {
      // render's two images differ, and the frame is nearer the new one than the previous one.
      EXPECT_LT(comparePngs(ref, before).psnr, 99.0) << "the option changed nothing in render";
      ImageDifference previous = compareWithPng(shown, w, h, before);
      EXPECT_GT(previous.meanAbs, own.meanAbs) << "the frame did not change as render's does";
    }
    before = ref;
  }
  EXPECT_EQ(server.stop(), 0) << server.stderrText();
}

} // namespace
} // namespace pointrast::test
