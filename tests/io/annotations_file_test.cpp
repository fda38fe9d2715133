// The annotations file: every kind round-trips exactly (doubles included), measured values are written for
// people and measured again on load, and hostile files are refused with one line naming the entry.
#include "io/annotations_file.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/error.h"

namespace pointrast {
namespace {

Annotations everyKind() {
  Annotations set;
  set.unit = "m";
  auto add = [&](AnnotationKind kind, std::vector<glm::dvec3> points, std::string text = {}) {
    Annotation a;
    a.kind = kind;
    a.points = std::move(points);
    a.text = std::move(text);
    set.items.push_back(a);
    return &set.items.back();
  };
  // Values that need all 17 digits, and UTM-sized ones.
  add(AnnotationKind::Point, {{0.1, 1.0 / 3.0, 2.0 / 7.0}}, "tree");
  add(AnnotationKind::Distance, {{636123.456789, 849012.3456789, 412.10000000000002}, {636200.1, 849100.2, 430.5}, {1e-300, -5e14, 7}});
  add(AnnotationKind::Height, {{1, 2, 3}, {4, 6, -9}})->color = std::array<uint8_t, 3>{1, 2, 255};
  add(AnnotationKind::Area, {{0, 0, 0}, {10, 0, 1}, {10, 10, 2}, {0, 10, 3}}, "roof \xC2\xB0 \"quoted\"");
  add(AnnotationKind::Angle, {{1, 0, 0}, {0, 0, 0}, {0.7071067811865476, 0.7071067811865475, 0}});
  add(AnnotationKind::Label, {{5, 5, 5}}, "line one\nline two");
  Annotation box;
  box.kind = AnnotationKind::ClipBox;
  box.box.center = {636000.5, 849000.25, 400.125};
  const double c = std::cos(0.3), s = std::sin(0.3);
  box.box.axes = {glm::dvec3(c, s, 0), glm::dvec3(-s, c, 0), glm::dvec3(0, 0, 1)};
  box.box.halfExtent = {10.1, 20.2, 30.3};
  set.items.push_back(box);
  Annotation polygon;
  polygon.kind = AnnotationKind::ClipPolygon;
  polygon.polygon.vertices = {{0.1, 0.2}, {5.3, 0.4}, {2.5, 7.7}};
  polygon.polygon.zMax = 99.9;
  polygon.text = "unbounded below";
  set.items.push_back(polygon);
  return set;
}

void expectEqual(const Annotations& a, const Annotations& b) {
  EXPECT_EQ(a.unit, b.unit);
  ASSERT_EQ(a.items.size(), b.items.size());
  for (size_t i = 0; i < a.items.size(); ++i) {
    const Annotation &x = a.items[i], &y = b.items[i];
    EXPECT_EQ(x.kind, y.kind) << i;
    EXPECT_EQ(x.text, y.text) << i;
    EXPECT_EQ(x.color, y.color) << i;
    EXPECT_EQ(x.points, y.points) << i; // bit-exact doubles
    EXPECT_EQ(x.box.center, y.box.center) << i;
    EXPECT_EQ(x.box.axes, y.box.axes) << i;
    EXPECT_EQ(x.box.halfExtent, y.box.halfExtent) << i;
    EXPECT_EQ(x.polygon.vertices, y.polygon.vertices) << i;
    EXPECT_EQ(x.polygon.zMin, y.polygon.zMin) << i;
    EXPECT_EQ(x.polygon.zMax, y.polygon.zMax) << i;
  }
}

TEST(AnnotationsFile, RoundTripsExactly) {
  const Annotations set = everyKind();
  for (const Annotation& a : set.items)
    ASSERT_EQ(annotationProblem(a), "") << annotationKindName(a.kind);
  const std::string text = io::annotationsJson(set);
  const Annotations back = io::parseAnnotations(text, "a.json");
  expectEqual(set, back);
  EXPECT_EQ(io::annotationsJson(back), text);

  const auto file = std::filesystem::temp_directory_path() / ("annotations_" + std::to_string(::getpid()) + ".json");
  io::saveAnnotations(file, set);
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".partial"));
  expectEqual(set, io::loadAnnotations(file));
  std::filesystem::remove(file);
}

TEST(AnnotationsFile, MeasuredValuesAreWrittenButMeasuredAgainOnLoad) {
  Annotations set;
  Annotation d;
  d.kind = AnnotationKind::Distance;
  d.points = {{0, 0, 0}, {3, 4, 0}, {3, 4, 12}};
  set.items.push_back(d);
  nlohmann::json j = nlohmann::json::parse(io::annotationsJson(set));
  const nlohmann::json& measured = j["annotations"][0]["measured"];
  EXPECT_EQ(measured["length"].get<double>(), 17.0);
  EXPECT_EQ(measured["segments"], nlohmann::json::array({5.0, 12.0}));
  // A file whose stated values lie: loading measures the points, and saving writes the truth.
  j["annotations"][0]["measured"]["length"] = 1000.0;
  const Annotations loaded = io::parseAnnotations(j.dump(), "lying.json");
  EXPECT_EQ(measure(loaded.items[0]).length, 17.0);
  EXPECT_EQ(nlohmann::json::parse(io::annotationsJson(loaded))["annotations"][0]["measured"]["length"], 17.0);
}

std::string refusal(const std::string& text) {
  try {
    io::parseAnnotations(text, "bad.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(AnnotationsFile, HostileFilesGiveOneLineNamingTheEntry) {
  struct Case {
    const char* text;
    const char* expected;
  };
  const std::string ok = R"({"type": "point", "points": [[0, 0, 0]]})";
  const Case cases[] = {
      {"", "not a JSON file"},
      {"{\"version\": 1, \"annotations\": [", "not a JSON file"},
      {"[]", "not an annotations file"},
      {R"({"version": 2, "annotations": []})", "unsupported annotations version"},
      {R"({"version": "1", "annotations": []})", "unsupported annotations version"},
      {R"({"version": 1, "annotations": {}})", "\"annotations\" must be an array"},
      {R"({"version": 1, "annotations": [], "extra": 1})", "unknown key \"extra\""},
      {R"({"version": 1, "unit": 5, "annotations": []})", "\"unit\" must be a short string"},
      {R"({"version": 1, "annotations": [7]})", "annotation 1: not an object"},
      {R"({"version": 1, "annotations": [{"points": [[0,0,0]]}]})", "annotation 1: \"type\" is missing"},
      {R"({"version": 1, "annotations": [{"type": "volume"}]})", "annotation 1: unknown type"},
      {R"({"version": 1, "annotations": [{"type": "distance", "points": [[0,0,0]]}]})",
       "annotation 1 (distance): needs at least 2 points, not 1"},
      {R"({"version": 1, "annotations": [{"type": "point", "points": [[0,0,0]]}, {"type": "angle", "points": [[0,0,0],[1,1,1]]}]})",
       "annotation 2 (angle): needs exactly 3 points, not 2"},
      {R"({"version": 1, "annotations": [{"type": "point", "points": [[0,0]]}]})",
       "annotation 1 (point): each point must be an array of 3 numbers"},
      {R"({"version": 1, "annotations": [{"type": "point", "points": [[0,"x",0]]}]})",
       "annotation 1 (point): each point must be a number"},
      {R"({"version": 1, "annotations": [{"type": "point", "points": [[0,1e400,0]]}]})", "not a JSON file"},
      {R"({"version": 1, "annotations": [{"type": "point", "points": [[0,1e300,0]]}]})", "not a finite coordinate"},
      {R"({"version": 1, "annotations": [{"type": "point", "points": 3}]})", "\"points\" must be an array"},
      {R"({"version": 1, "annotations": [{"type": "point", "points": [[0,0,0]], "pointz": 1}]})",
       "annotation 1 (point): unknown key \"pointz\""},
      {R"({"version": 1, "annotations": [{"type": "label", "points": [[0,0,0]]}]})", "a label needs a text"},
      {R"({"version": 1, "annotations": [{"type": "label", "text": 5, "points": [[0,0,0]]}]})",
       "\"text\" must be a string"},
      {R"({"version": 1, "annotations": [{"type": "point", "color": [0, 256, 0], "points": [[0,0,0]]}]})",
       "\"color\" must be an array of 3 integers 0..255"},
      {R"({"version": 1, "annotations": [{"type": "clip-box", "center": [0,0,0], "axes": [[1,0,0],[1,0,0],[0,0,1]], "half_extent": [1,1,1]}]})",
       "annotation 1 (clip-box): the box's axes are not orthonormal"},
      {R"({"version": 1, "annotations": [{"type": "clip-box", "center": [0,0,0], "half_extent": [1,1,1]}]})",
       "annotation 1 (clip-box): \"axes\" is missing"},
      {R"({"version": 1, "annotations": [{"type": "clip-box", "center": [0,0,0], "axes": [[1,0,0],[0,1,0],[0,0,1]], "half_extent": [1,-1,1]}]})",
       "half extents must be finite and >= 0"},
      {R"({"version": 1, "annotations": [{"type": "clip-polygon", "vertices": [[0,0],[1,0]]}]})",
       "annotation 1 (clip-polygon): the polygon needs at least 3 vertices"},
      {R"({"version": 1, "annotations": [{"type": "clip-polygon", "vertices": [[0,0],[1,0],[0,1]], "z_min": 3, "z_max": 2}]})",
       "z range is empty"},
      {R"({"version": 1, "annotations": [{"type": "clip-polygon", "vertices": [[0,0],[1,0],[0,1]], "points": []}]})",
       "unknown key \"points\""},
  };
  for (const Case& c : cases) {
    const std::string message = refusal(c.text);
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.text << "\n  -> " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind("bad.json: ", 0), 0u) << message;
  }
  EXPECT_EQ(refusal(R"({"version": 1, "annotations": [)" + ok + "]}"), "(accepted)");
  // Deep nesting and a long text stay errors, not crashes.
  EXPECT_NE(refusal(std::string(100000, '[') + std::string(100000, ']')).find("not an annotations file"),
            std::string::npos);
  const std::string longText(io::kMaxAnnotationText + 1, 'x');
  EXPECT_NE(refusal(R"({"version": 1, "annotations": [{"type": "label", "text": ")" + longText +
                    R"(", "points": [[0,0,0]]}]})")
                .find("longer than"),
            std::string::npos);
}

TEST(AnnotationsFile, MissingAndOversizedFilesAreRefused) {
  EXPECT_THROW(io::loadAnnotations("/nonexistent/annotations.json"), InputError);
  EXPECT_THROW(io::loadAnnotations(std::filesystem::temp_directory_path()), InputError);
}

} // namespace
} // namespace pointrast
