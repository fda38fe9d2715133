// The browser viewer's protocol: every client message is one of a few exact shapes, anything else is
// refused with a reason; the frame header round-trips.
#include "view/web/protocol.h"

#include <gtest/gtest.h>

#include "base/error.h"
#include "view/web/client.h"

namespace pointrast::view::web {
namespace {

const std::vector<Method> kMethods = {pointMethod("atomicmin"), pointMethod("batch")};

ClientMessage accepted(const std::string& text) {
  auto parsed = parseClientMessage(text, kMethods);
  if (auto* why = std::get_if<std::string>(&parsed)) ADD_FAILURE() << text << ": " << *why;
  return std::holds_alternative<ClientMessage>(parsed) ? std::get<ClientMessage>(parsed) : ClientMessage{};
}

std::string refused(const std::string& text) {
  auto parsed = parseClientMessage(text, kMethods);
  if (std::holds_alternative<ClientMessage>(parsed)) {
    ADD_FAILURE() << text << " was accepted";
    return "";
  }
  return std::get<std::string>(parsed);
}

TEST(Protocol, AcceptsEveryShapeThePageSends) {
  ClientMessage m = accepted(R"({"t":"resize","w":1920,"h":1080})");
  EXPECT_EQ(m.type, MessageType::Resize);
  EXPECT_EQ(m.width, 1920u);
  m = accepted(R"({"t":"down","b":2,"x":0.25,"y":0.75,"seq":7})");
  EXPECT_EQ(m.type, MessageType::Down);
  EXPECT_EQ(m.button, MouseButton::Right);
  EXPECT_EQ(m.position, glm::dvec2(0.25, 0.75));
  EXPECT_EQ(m.seq, 7u);
  EXPECT_EQ(accepted(R"({"t":"down","b":1,"x":0,"y":0})").button, MouseButton::Middle);
  EXPECT_EQ(accepted(R"({"t":"move","x":-1.5,"y":2,"seq":8})").position, glm::dvec2(-1.5, 2));
  EXPECT_EQ(accepted(R"({"t":"up","b":0,"x":1,"y":1})").button, MouseButton::Left);
  EXPECT_EQ(accepted(R"({"t":"dblclick","x":0.5,"y":0.5})").type, MessageType::DoubleClick);
  EXPECT_DOUBLE_EQ(accepted(R"({"t":"wheel","x":0.5,"y":0.5,"steps":-1.25})").steps, -1.25);
  m = accepted(R"({"t":"key","key":"Forward","down":true,"shift":true})");
  EXPECT_EQ(m.key, Key::Forward);
  EXPECT_TRUE(m.down && m.shift);
  EXPECT_EQ(accepted(R"({"t":"key","key":"ViewIso","down":false})").key, Key::ViewIso);
  m = accepted(R"({"t":"settings","method":"batch","background":[64,64,64]})");
  EXPECT_EQ(m.settings.method, pointMethod("batch"));
  EXPECT_EQ(m.settings.background, 0xFF404040u);
  m = accepted(R"({"t":"options","supersample":4,"keyframeSeconds":0.5})");
  EXPECT_EQ(m.supersample, 4u);
  EXPECT_DOUBLE_EQ(*m.keyframeSeconds, 0.5);
  m = accepted(R"({"t":"stream","motionScale":0.25,"quality":95,"motionQuality":40})");
  EXPECT_DOUBLE_EQ(*m.motionScale, 0.25);
  EXPECT_EQ(*m.quality, 95);
  EXPECT_EQ(accepted(R"({"t":"action","name":"downloadPath"})").action, ClientAction::DownloadPath);
  EXPECT_EQ(accepted(R"({"t":"ack","frame":12})").frame, 12u);
}

TEST(Protocol, RefusesEverythingElseWithAReason) {
  EXPECT_EQ(refused(""), "not JSON");
  EXPECT_EQ(refused("{"), "not JSON");
  EXPECT_EQ(refused("\xff\xfe"), "not JSON");
  EXPECT_EQ(refused("[1,2]"), "a message must be a JSON object");
  EXPECT_EQ(refused(R"({"x":1})"), "missing \"t\"");
  EXPECT_EQ(refused(R"({"t":5})"), "\"t\" must be a string");
  EXPECT_EQ(refused(R"({"t":"quit"})"), "unknown message type");
  EXPECT_EQ(refused(R"({"t":"move","x":0,"y":0,"path":"/etc/passwd"})"), "unknown field \"path\"");
  EXPECT_EQ(refused(R"({"t":"move","x":0})"), "missing \"y\"");
  EXPECT_EQ(refused(R"({"t":"move","x":"0","y":0})"), "\"x\" must be a number");
  EXPECT_EQ(refused(R"({"t":"move","x":1e308,"y":0})"), "\"x\" is out of range");
  EXPECT_EQ(refused(R"({"t":"move","x":-5,"y":0})"), "\"x\" is out of range");
  EXPECT_EQ(refused(R"({"t":"down","b":3,"x":0,"y":0})"), "\"b\" is out of range");
  EXPECT_EQ(refused(R"({"t":"down","b":-1,"x":0,"y":0})"), "\"b\" must be a non-negative integer");
  EXPECT_EQ(refused(R"({"t":"resize","w":0,"h":10})"), "\"w\" is out of range");
  EXPECT_EQ(refused(R"({"t":"resize","w":100000,"h":10})"), "\"w\" is out of range");
  EXPECT_EQ(refused(R"({"t":"resize","w":1.5,"h":10})"), "\"w\" must be a non-negative integer");
  EXPECT_EQ(refused(R"({"t":"wheel","x":0,"y":0,"steps":51})"), "\"steps\" is out of range");
  EXPECT_EQ(refused(R"({"t":"key","key":"Quit","down":true})"), "unknown key");
  EXPECT_EQ(refused(R"({"t":"key","key":"Forward","down":1})"), "\"down\" must be true or false");
  EXPECT_EQ(refused(R"({"t":"settings","method":"hqs"})"), "\"method\" is not a method this device runs");
  EXPECT_EQ(refused(R"({"t":"settings","background":[1,2]})"), "\"background\" must be [r, g, b]");
  EXPECT_EQ(refused(R"({"t":"settings","background":[1,2,256]})"), "\"background\" takes 0..255");
  EXPECT_EQ(refused(R"({"t":"settings"})"), "\"settings\" changes nothing");
  EXPECT_EQ(refused(R"({"t":"options","supersample":3})"), "\"supersample\" takes 1, 2 or 4");
  EXPECT_EQ(refused(R"({"t":"options","keyframeSeconds":0})"), "\"keyframeSeconds\" is out of range");
  EXPECT_EQ(refused(R"({"t":"stream","motionScale":0.1})"), "\"motionScale\" is out of range");
  EXPECT_EQ(refused(R"({"t":"stream","quality":5})"), "\"quality\" is out of range");
  EXPECT_EQ(refused(R"({"t":"action","name":"shutdown"})"), "unknown action");
  EXPECT_EQ(refused(R"({"t":"ack","frame":-1})"), "\"frame\" must be a non-negative integer");
  EXPECT_EQ(refused(R"({"t":"move","x":0,"y":0,"seq":4294967296})"), "\"seq\" is out of range");
  EXPECT_EQ(refused(std::string(kMaxMessageBytes + 1, ' ')), "message too long");
  EXPECT_EQ(refused(std::string("{\"t\":\"move\",\"x\":0,\"y\":0}\0garbage", 32)), "a NUL byte");
  // Deep nesting within the size bound is only a refusal, not a crash.
  EXPECT_EQ(refused(std::string(500, '[') + std::string(500, ']')), "a message must be a JSON object");
}

TEST(Protocol, SettingsCarryEveryRenderOptionAViewerOffers) {
  ClientMessage m = accepted(
      R"({"t":"settings","depth":"int40","color":"intensity","colorRange":[10,2000],"pointSize":3,)"
      R"("pointSizeMax":12,"pointShape":"disc","pointSizeMode":"attenuated","dilate":2,"edlStrength":1.5,)"
      R"("edlRadius":2,"minNodePx":50,"pointBudget":1000000,"gpuMemory":268435456})");
  const SettingsChange& c = m.settings;
  EXPECT_EQ(c.depth, DepthMode::Int40);
  EXPECT_TRUE(c.color);
  EXPECT_EQ(c.colorSource, DisplayColorMode::Source::Intensity);
  EXPECT_TRUE(c.range);
  ASSERT_TRUE(c.colorRange);
  EXPECT_EQ(c.colorRange->hi, 2000);
  EXPECT_EQ(c.pointSize, 3.0f);
  EXPECT_EQ(c.pointShape, PointShape::Disc);
  EXPECT_EQ(c.pointSizeMode, PointSizeMode::Attenuated);
  EXPECT_EQ(c.dilate, 2u);
  EXPECT_EQ(c.edlStrength, 1.5f);
  EXPECT_EQ(c.pointBudget, 1000000u);
  EXPECT_EQ(c.gpuMemory, 268435456u);
  ViewSettings s = applySettings(ViewSettings{}, c);
  EXPECT_EQ(s.depth, DepthMode::Int40);
  EXPECT_EQ(s.post.maxPointSize, 12.0f);
  EXPECT_EQ(s.post.edlRadius, 2.0f);
  EXPECT_EQ(s.minNodePx, 50);
  EXPECT_EQ(describeSettings(s),
            "--depth int40 --color intensity --color-range 10,2000 --point-size 3 "
            "--point-shape disc --point-size-mode attenuated --point-size-max 12 --dilate 2 "
            "--edl --edl-strength 1.5 --edl-radius 2 --min-node-px 50 --point-budget 1000000 "
            "--gpu-memory 268435456");
  // "auto" and null go back to the defaults; a new source drops the old range.
  ViewSettings automatic = applySettings(s, accepted(R"({"t":"settings","color":"auto"})").settings);
  EXPECT_FALSE(automatic.colorSource);
  EXPECT_FALSE(automatic.colorRange);
  EXPECT_FALSE(applySettings(s, accepted(R"({"t":"settings","colorRange":null})").settings).colorRange);
  EXPECT_EQ(applySettings(s, accepted(R"({"t":"settings","color":"return"})").settings).colorSource,
            DisplayColorMode::Source::ReturnNumber);
  // A whole render would refuse is refused here too: a range for colors without a ramp.
  ViewSettings rgb = applySettings({}, accepted(R"({"t":"settings","color":"rgb"})").settings);
  EXPECT_THROW(applySettings(rgb, accepted(R"({"t":"settings","colorRange":[0,1]})").settings), InputError);
  EXPECT_EQ(describeSettings(ViewSettings{}), "");
}

TEST(Protocol, RefusesSettingsOutOfRenderRanges) {
  EXPECT_EQ(refused(R"({"t":"settings","depth":"int64"})"), "unknown \"depth\"");
  EXPECT_EQ(refused(R"({"t":"settings","color":"red"})"), "unknown \"color\"");
  EXPECT_EQ(refused(R"({"t":"settings","colorRange":[5,5]})"), "\"colorRange\" must be finite with lo < hi");
  EXPECT_EQ(refused(R"({"t":"settings","colorRange":[0]})"), "\"colorRange\" must be [lo, hi] or null");
  EXPECT_EQ(refused(R"({"t":"settings","colorRange":["0",1]})"), "\"colorRange\" must be [lo, hi] or null");
  EXPECT_EQ(refused(R"({"t":"settings","pointSize":0.5})"), "\"pointSize\" is out of range");
  EXPECT_EQ(refused(R"({"t":"settings","pointSize":33})"), "\"pointSize\" is out of range");
  EXPECT_EQ(refused(R"({"t":"settings","pointShape":"star"})"), "unknown \"pointShape\"");
  EXPECT_EQ(refused(R"({"t":"settings","pointSizeMode":"adaptive"})"), "unknown \"pointSizeMode\"");
  EXPECT_EQ(refused(R"({"t":"settings","dilate":9})"), "\"dilate\" is out of range");
  EXPECT_EQ(refused(R"({"t":"settings","dilate":1.5})"), "\"dilate\" must be a non-negative integer");
  EXPECT_EQ(refused(R"({"t":"settings","edlStrength":-1})"), "\"edlStrength\" is out of range");
  EXPECT_EQ(refused(R"({"t":"settings","edlStrength":11})"), "\"edlStrength\" is out of range");
  EXPECT_EQ(refused(R"({"t":"settings","edlRadius":0})"), "\"edlRadius\" is out of range");
  EXPECT_EQ(refused(R"({"t":"settings","minNodePx":-1})"), "\"minNodePx\" is out of range");
  EXPECT_EQ(refused(R"({"t":"settings","pointBudget":-1})"),
            "\"pointBudget\" must be a non-negative integer");
  EXPECT_EQ(refused(R"({"t":"settings","pointBudget":1e300})"),
            "\"pointBudget\" must be a non-negative integer");
  EXPECT_EQ(refused(R"({"t":"settings","gpuMemory":18446744073709551615})"), "\"gpuMemory\" is out of range");
  EXPECT_EQ(refused(R"({"t":"settings","seq":3})"), "\"settings\" changes nothing");
  EXPECT_EQ(refused(R"({"t":"settings","pointsize":3})"), "unknown field \"pointsize\"");
}

TEST(Protocol, KeyNamesRoundTrip) {
  for (int k = int(Key::Forward); k <= int(Key::ViewIso); ++k)
    EXPECT_EQ(keyFromName(keyName(Key(k))), Key(k)) << k;
  EXPECT_FALSE(keyFromName(keyName(Key::Quit)));
}

TEST(Protocol, FrameHeaderRoundTrips) {
  FrameHeader h;
  h.frame = 17;
  h.seq = 4000000000u;
  h.width = 960;
  h.height = 540;
  h.viewWidth = 1920;
  h.viewHeight = 1080;
  h.quality = 60;
  h.flags = kFrameFull;
  h.renderMs = 1.5f;
  h.encodeMs = 2.25f;
  uint8_t bytes[kFrameHeaderBytes];
  writeFrameHeader(h, bytes);
  EXPECT_EQ(bytes[0], 'P');
  EXPECT_EQ(bytes[3], '1');
  FrameHeader r = readFrameHeader(bytes);
  EXPECT_EQ(r.frame, 17u);
  EXPECT_EQ(r.seq, 4000000000u);
  EXPECT_EQ(r.width, 960);
  EXPECT_EQ(r.viewHeight, 1080);
  EXPECT_EQ(r.quality, 60);
  EXPECT_EQ(r.flags, kFrameFull);
  EXPECT_FLOAT_EQ(r.encodeMs, 2.25f);
}

TEST(Viewports, ClampKeepsTheAspectAndScaleRounds) {
  EXPECT_EQ(clampViewport(1920, 1080, {3840, 2160}), (Viewport{1920, 1080}));
  EXPECT_EQ(clampViewport(7680, 4320, {3840, 2160}), (Viewport{3840, 2160}));
  EXPECT_EQ(clampViewport(4000, 1000, {3840, 2160}), (Viewport{3840, 960}));
  EXPECT_EQ(clampViewport(16384, 1, {3840, 2160}), (Viewport{3840, 1}));
  EXPECT_EQ(scaleViewport({1920, 1080}, 0.5), (Viewport{960, 540}));
  EXPECT_EQ(scaleViewport({1, 3}, 0.25), (Viewport{1, 1}));
}

} // namespace
} // namespace pointrast::view::web
