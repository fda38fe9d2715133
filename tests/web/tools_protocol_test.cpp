// The pick, measure and clip messages of the browser viewer's protocol, and the export's query: exact
// shapes accepted, anything else refused with a reason.
#include <gtest/gtest.h>

#include "base/error.h"
#include "view/web/export.h"
#include "view/web/protocol.h"

namespace pointrast::view::web {
namespace {

const std::vector<Method> kMethods = {pointMethod("atomicmin")};

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

TEST(ToolsProtocol, PickAndMeasureMessages) {
  ClientMessage m = accepted(R"({"t":"pickpoint","x":0.5,"y":0.25})");
  EXPECT_EQ(m.type, MessageType::PickPoint);
  EXPECT_EQ(m.position, glm::dvec2(0.5, 0.25));
  EXPECT_FALSE(m.measure);
  EXPECT_EQ(accepted(R"({"t":"pickpoint","x":0,"y":0,"measure":"area"})").measure, AnnotationKind::Area);
  EXPECT_EQ(accepted(R"({"t":"pickpoint","x":0,"y":0,"measure":"height"})").measure, AnnotationKind::Height);
  EXPECT_EQ(refused(R"({"t":"pickpoint","x":0,"y":0,"measure":"angle"})"), "unknown measurement");
  EXPECT_EQ(refused(R"({"t":"pickpoint","x":0})"), "missing \"y\"");
  m = accepted(R"({"t":"measure","op":"delete","index":3})");
  EXPECT_EQ(m.measureOp, MeasureOp::Delete);
  EXPECT_EQ(m.index, 3u);
  EXPECT_EQ(accepted(R"({"t":"measure","op":"download"})").measureOp, MeasureOp::Download);
  EXPECT_EQ(refused(R"({"t":"measure","op":"delete"})"), "missing \"index\"");
  EXPECT_EQ(refused(R"({"t":"measure","op":"save","index":1})"), "unknown measure operation");
  m = accepted(R"({"t":"measure","op":"move","x":0.25,"y":0.5,"tx":0.75,"ty":1})");
  EXPECT_EQ(m.measureOp, MeasureOp::Move);
  EXPECT_EQ(m.position, glm::dvec2(0.25, 0.5));
  EXPECT_EQ(m.target, glm::dvec2(0.75, 1));
  EXPECT_EQ(refused(R"({"t":"measure","op":"move","x":0.25,"y":0.5,"tx":0.75})"), "missing \"ty\"");
  EXPECT_NE(refused(R"({"t":"measure","op":"move","x":0.25,"y":0.5,"tx":"a","ty":1})"), "");
}

TEST(ToolsProtocol, ClipBoxSettings) {
  ClientMessage m = accepted(R"({"t":"settings","clipBox":[0,1,2,3,4,5],"clipMode":"outside"})");
  ViewSettings s = applySettings(ViewSettings{}, m.settings);
  ASSERT_EQ(s.filter.boxes.size(), 1u);
  EXPECT_EQ(s.filter.boxes[0].min, glm::dvec3(0, 1, 2));
  EXPECT_EQ(s.filter.boxes[0].max, glm::dvec3(3, 4, 5));
  EXPECT_EQ(s.filter.clipMode, ClipMode::Outside);
  s = applySettings(s, accepted(R"({"t":"settings","clipBox":null})").settings);
  EXPECT_TRUE(s.filter.boxes.empty());
  EXPECT_EQ(refused(R"({"t":"settings","clipBox":[3,0,0,0,1,1]})"),
            "\"clipBox\" is [min corner, max corner]");
  EXPECT_EQ(refused(R"({"t":"settings","clipBox":[0,0,0,1,1]})"),
            "\"clipBox\" must be [x0, y0, z0, x1, y1, z1] or null");
  EXPECT_EQ(refused(R"({"t":"settings","clipMode":"highlight"})"), "\"clipMode\" takes inside or outside");
}

TEST(ExportQuery, ParsesTheBoxModeAndClasses) {
  PointFilter f = parseExportQuery("box=1%2C2,3,4,5,6&mode=outside&classes=2%2c6&token=abc");
  ASSERT_EQ(f.boxes.size(), 1u);
  EXPECT_EQ(f.boxes[0].max, glm::dvec3(4, 5, 6));
  EXPECT_EQ(f.clipMode, ClipMode::Outside);
  ASSERT_TRUE(f.classes);
  EXPECT_EQ(f.classes->count(), 2u);
  EXPECT_TRUE(f.classes->test(6));
  EXPECT_FALSE(parseExportQuery("").active());
  for (const char* bad :
       {"box=1,2,3", "box=1,2,3,0,5,6", "box=1,2,3,4,5,nan", "mode=inside", "classes=256", "classes=1.5",
        "what=1", "box=1,2,3,4,5,6&box=1,2,3,4,5,6", "box=1%2", "box=1%zz,2,3,4,5,6"})
    EXPECT_THROW(parseExportQuery(bad), InputError) << bad;
}

TEST(ExportQuery, OnlyALasFamilyFileCanBeExported) {
  EXPECT_FALSE(exportSource("terrain").file);
  EXPECT_NE(exportSource("terrain").whyNot.find("generated scene"), std::string::npos);
  EXPECT_FALSE(exportSource("/").file);
}

} // namespace
} // namespace pointrast::view::web
