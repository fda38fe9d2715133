#include "io/annotations_file.h"

#include <cassert>
#include <cmath>
#include <fstream>
#include <limits>
#include <system_error>

#include <nlohmann/json.hpp>

#include "base/error.h"
#include "io/io_util.h"

namespace pointrast::io {

namespace {

using nlohmann::json;

const json* member(const json& j, const char* key) {
  const auto found = j.find(key);
  return found == j.end() ? nullptr : &*found;
}

double number(const json& j, const std::string& what, const std::string& where) {
  if (!j.is_number()) throw InputError(where + ": " + what + " must be a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) throw InputError(where + ": " + what + " must be finite");
  return v;
}

template <int N> glm::vec<N, double> vector(const json& j, const std::string& what, const std::string& where) {
  if (!j.is_array() || j.size() != N)
    throw InputError(where + ": " + what + " must be an array of " + std::to_string(N) + " numbers");
  glm::vec<N, double> v;
  for (int i = 0; i < N; ++i)
    v[i] = number(j[size_t(i)], what, where);
  return v;
}

const json& required(const json& entry, const char* key, const std::string& where) {
  const json* j = member(entry, key);
  if (!j) throw InputError(where + ": \"" + key + "\" is missing");
  return *j;
}

// The keys an entry of each kind may hold: a misspelt key is refused rather than silently ignored.
bool knownKey(AnnotationKind kind, const std::string& key) {
  if (key == "type" || key == "text" || key == "color" || key == "measured") return true;
  switch (kind) {
  case AnnotationKind::ClipBox:
    return key == "center" || key == "axes" || key == "half_extent";
  case AnnotationKind::ClipPolygon:
    return key == "vertices" || key == "z_min" || key == "z_max";
  default:
    return key == "points";
  }
}

Annotation parseEntry(const json& entry, const std::string& where) {
  if (!entry.is_object()) throw InputError(where + ": not an object");
  const json& type = required(entry, "type", where);
  if (!type.is_string()) throw InputError(where + ": \"type\" must be a string");
  const std::optional<AnnotationKind> kind = parseAnnotationKind(type.get<std::string>());
  if (!kind)
    throw InputError(where + ": unknown type; choose point, distance, height, area, angle, label, clip-box or "
                             "clip-polygon");
  const std::string named = where + " (" + annotationKindName(*kind) + ")";
  for (const auto& item : entry.items())
    if (!knownKey(*kind, item.key())) throw InputError(named + ": unknown key \"" + item.key() + "\"");
  Annotation a;
  a.kind = *kind;
  if (const json* text = member(entry, "text")) {
    if (!text->is_string()) throw InputError(named + ": \"text\" must be a string");
    a.text = text->get<std::string>();
    if (a.text.size() > kMaxAnnotationText)
      throw InputError(named + ": \"text\" is longer than " + std::to_string(kMaxAnnotationText) + " bytes");
  }
  if (const json* color = member(entry, "color")) {
    if (!color->is_array() || color->size() != 3)
      throw InputError(named + ": \"color\" must be an array of 3 integers 0..255");
    std::array<uint8_t, 3> rgb{};
    for (size_t c = 0; c < 3; ++c) {
      const json& v = (*color)[c];
      if (!v.is_number_integer() || v.get<int64_t>() < 0 || v.get<int64_t>() > 255)
        throw InputError(named + ": \"color\" must be an array of 3 integers 0..255");
      rgb[c] = uint8_t(v.get<int64_t>());
    }
    a.color = rgb;
  }
  if (a.kind == AnnotationKind::ClipBox) {
    a.box.center = vector<3>(required(entry, "center", named), "\"center\"", named);
    const json& axes = required(entry, "axes", named);
    if (!axes.is_array() || axes.size() != 3) throw InputError(named + ": \"axes\" must be an array of 3 vectors");
    for (size_t i = 0; i < 3; ++i)
      a.box.axes[i] = vector<3>(axes[i], "each of \"axes\"", named);
    a.box.halfExtent = vector<3>(required(entry, "half_extent", named), "\"half_extent\"", named);
  } else if (a.kind == AnnotationKind::ClipPolygon) {
    const json& vertices = required(entry, "vertices", named);
    if (!vertices.is_array()) throw InputError(named + ": \"vertices\" must be an array of [x, y]");
    for (const json& v : vertices)
      a.polygon.vertices.push_back(vector<2>(v, "each vertex", named));
    if (const json* z = member(entry, "z_min")) a.polygon.zMin = number(*z, "\"z_min\"", named);
    if (const json* z = member(entry, "z_max")) a.polygon.zMax = number(*z, "\"z_max\"", named);
  } else {
    const json& points = required(entry, "points", named);
    if (!points.is_array()) throw InputError(named + ": \"points\" must be an array of [x, y, z]");
    for (const json& p : points)
      a.points.push_back(vector<3>(p, "each point", named));
  }
  // "measured" is the writer's note for people; it is ignored and measured again.
  if (const std::string problem = annotationProblem(a); !problem.empty()) throw InputError(named + ": " + problem);
  return a;
}

json point(const glm::dvec3& p) {
  return json::array({p.x, p.y, p.z});
}

json measuredJson(const Annotation& a) {
  const Measurement m = measure(a);
  switch (a.kind) {
  case AnnotationKind::Distance:
    return {{"segments", m.segments}, {"length", m.length}};
  case AnnotationKind::Height:
    return {{"dz", m.dz}, {"horizontal", m.horizontal}, {"slope", m.slope}};
  case AnnotationKind::Area:
    return {{"area", m.area}, {"perimeter", m.perimeter}, {"perimeter_3d", m.perimeter3d}};
  case AnnotationKind::Angle:
    return {{"degrees", m.degrees}};
  default:
    return nullptr;
  }
}

json entryJson(const Annotation& a) {
  assert(annotationProblem(a).empty());
  json j;
  j["type"] = annotationKindName(a.kind);
  if (!a.text.empty()) j["text"] = a.text;
  if (a.color) j["color"] = {(*a.color)[0], (*a.color)[1], (*a.color)[2]};
  if (a.kind == AnnotationKind::ClipBox) {
    j["center"] = point(a.box.center);
    j["axes"] = {point(a.box.axes[0]), point(a.box.axes[1]), point(a.box.axes[2])};
    j["half_extent"] = point(a.box.halfExtent);
  } else if (a.kind == AnnotationKind::ClipPolygon) {
    json vertices = json::array();
    for (const glm::dvec2& v : a.polygon.vertices)
      vertices.push_back({v.x, v.y});
    j["vertices"] = vertices;
    // An unbounded side is left out (JSON has no infinity).
    if (std::isfinite(a.polygon.zMin)) j["z_min"] = a.polygon.zMin;
    if (std::isfinite(a.polygon.zMax)) j["z_max"] = a.polygon.zMax;
  } else {
    json points = json::array();
    for (const glm::dvec3& p : a.points)
      points.push_back(point(p));
    j["points"] = points;
  }
  if (json measured = measuredJson(a); !measured.is_null()) j["measured"] = measured;
  return j;
}

} // namespace

Annotations parseAnnotations(const std::string& text, const std::string& name) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw InputError(name + ": not a JSON file");
  if (!j.is_object() || !j.contains("annotations"))
    throw InputError(name + ": not an annotations file (an object with \"version\" and \"annotations\")");
  const json* version = member(j, "version");
  if (!version || !version->is_number_integer() || version->get<int64_t>() != kAnnotationsVersion)
    throw InputError(name + ": unsupported annotations version (this pointrast reads version " +
                     std::to_string(kAnnotationsVersion) + ")");
  for (const auto& item : j.items())
    if (item.key() != "version" && item.key() != "unit" && item.key() != "annotations")
      throw InputError(name + ": unknown key \"" + item.key() + "\"");
  Annotations annotations;
  if (const json* unit = member(j, "unit")) {
    if (!unit->is_string() || unit->get<std::string>().size() > 16)
      throw InputError(name + ": \"unit\" must be a short string (\"m\", \"ft\")");
    annotations.unit = unit->get<std::string>();
  }
  const json& entries = j["annotations"];
  if (!entries.is_array()) throw InputError(name + ": \"annotations\" must be an array");
  for (size_t i = 0; i < entries.size(); ++i)
    annotations.items.push_back(parseEntry(entries[i], name + ": annotation " + std::to_string(i + 1)));
  return annotations;
}

std::string annotationsJson(const Annotations& annotations) {
  json entries = json::array();
  for (const Annotation& a : annotations.items)
    entries.push_back(entryJson(a));
  json j;
  j["version"] = kAnnotationsVersion;
  if (!annotations.unit.empty()) j["unit"] = annotations.unit;
  j["annotations"] = entries;
  // nlohmann writes each double with the shortest digits that read back the same value.
  return j.dump(2) + "\n";
}

Annotations loadAnnotations(const std::filesystem::path& file) {
  std::error_code error;
  const auto status = std::filesystem::status(file, error);
  if (error || !std::filesystem::exists(status)) throw InputError(file.string() + ": no such annotations file");
  if (!std::filesystem::is_regular_file(status)) throw InputError(file.string() + ": not a regular file");
  const uint64_t size = std::filesystem::file_size(file, error);
  if (error) throw InputError(file.string() + ": cannot read the file size");
  if (size > kMaxAnnotationsFileBytes)
    throw InputError(file.string() + ": " + std::to_string(size) + " bytes, larger than an annotations file may be (" +
                     std::to_string(kMaxAnnotationsFileBytes) + ")");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open the file");
  std::string text(size, '\0');
  in.read(text.data(), std::streamsize(size));
  if (uint64_t(in.gcount()) != size) throw InputError(file.string() + ": the file changed while being read");
  return parseAnnotations(text, file.string());
}

void saveAnnotations(const std::filesystem::path& file, const Annotations& annotations) {
  const std::string text = annotationsJson(annotations);
  detail::PartialFile out(file);
  out.write(text.data(), text.size());
  out.commit();
}

} // namespace pointrast::io
