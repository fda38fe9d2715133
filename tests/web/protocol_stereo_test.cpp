// The viewers' stereo and foveation settings: the page's "settings" fields within render's ranges, the
// settings as render options, and what a method cannot draw dropped.
#include <variant>

#include <gtest/gtest.h>

#include "view/web/protocol.h"

namespace pointrast::view::web {
namespace {

const std::vector<Method> kMethods = {pointMethod("atomicmin"), pointMethod("batch"), pointMethod("lod")};

std::variant<ClientMessage, std::string> parse(const std::string& text) {
  return parseClientMessage(text, kMethods);
}

TEST(ProtocolStereo, StereoAndFoveationFieldsBecomeRenderOptions) {
  auto parsed = parse(R"({"t":"settings","stereo":true,"ipd":0.5,"crossed":true,"foveated":true,)"
                      R"("foveaRadius":0.2,"foveaPeriphery":4})");
  ASSERT_TRUE(std::holds_alternative<ClientMessage>(parsed)) << std::get<std::string>(parsed);
  ViewSettings start;
  start.method = pointMethod("lod");
  const ViewSettings s = applySettings(start, std::get<ClientMessage>(parsed).settings);
  EXPECT_TRUE(s.stereo);
  EXPECT_EQ(s.eyes.separation, 0.5);
  EXPECT_TRUE(s.foveation.enabled);
  EXPECT_EQ(describeSettings(s), "--method lod --stereo --ipd 0.5 --stereo-layout cross-eyed --foveated "
                                 "--fovea-radius 0.2 --fovea-periphery 4");
  EXPECT_EQ(eyeViewport(s, {641, 480}), (Viewport{320, 480}));
  // A method of the 2021 paper draws one eye: stereo and foveation are dropped, the window is one view.
  ViewSettings mono = s;
  mono.method = pointMethod("atomicmin");
  EXPECT_EQ(describeSettings(mono), "");
  EXPECT_EQ(eyeViewport(mono, {641, 480}), (Viewport{641, 480}));
  // The batch methods draw stereo, not foveation.
  mono.method = pointMethod("batch");
  EXPECT_EQ(describeSettings(mono), "--method batch --stereo --ipd 0.5 --stereo-layout cross-eyed");
}

TEST(ProtocolStereo, OutOfRangeValuesAreRefused) {
  for (const char* text :
       {R"({"t":"settings","stereo":1})", R"({"t":"settings","ipd":-1})",
        R"({"t":"settings","foveaRadius":1.5})", R"({"t":"settings","foveaPeriphery":0.5})",
        R"({"t":"settings","foveated":"yes"})"}) {
    auto parsed = parse(text);
    EXPECT_TRUE(std::holds_alternative<std::string>(parsed)) << text << " was accepted";
  }
}

} // namespace
} // namespace pointrast::view::web
