// Potree 2.0 metadata.json: the attribute layout, written in PotreeConverter's field order and read
// defensively (every field the reader relies on checked for presence, type and range).
#include <algorithm>
#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "io/io_util.h"
#include "io/las/las_attributes.h"
#include "io/potree/potree_attributes.h"
#include "io/potree/potree_format.h"

namespace pointrast::io::potree {

using namespace detail;
using nlohmann::json;

namespace {

// Limits that no real octree reaches and that keep a hostile file's layout small.
constexpr uint64_t kMaxAttributes = 1024;
constexpr int kMaxAttributeSize = 4096;

int typeSize(const std::string& type) {
  if (type == "int8" || type == "uint8") return 1;
  if (type == "int16" || type == "uint16") return 2;
  if (type == "int32" || type == "uint32" || type == "float") return 4;
  if (type == "int64" || type == "uint64" || type == "double") return 8;
  return 0;
}

// The record field an attribute fills: name, type and shape must all be PotreeConverter's.
Field classify(const Attribute& a) {
  auto is = [&](const char* name, const char* type, int elements) {
    return a.name == name && a.type == type && a.numElements == elements &&
           a.size == elements * typeSize(a.type);
  };
  if (is("position", "int32", 3)) return Field::Position;
  if (is("rgb", "uint16", 3)) return Field::Rgb;
  if (is("intensity", "uint16", 1)) return Field::Intensity;
  if (is("return number", "uint8", 1)) return Field::ReturnNumber;
  if (is("classification", "uint8", 1)) return Field::Classification;
  if (is("point source id", "uint16", 1)) return Field::PointSourceId;
  return Field::Other;
}

Attribute makeAttribute(const char* name, const char* type, int elements) {
  Attribute a;
  a.name = name;
  a.type = type;
  a.numElements = elements;
  a.elementSize = typeSize(type);
  a.size = elements * a.elementSize;
  return a;
}

// ---- reading helpers: each names the field it checks ------------------------------------------------

class Reader {
public:
  explicit Reader(const std::filesystem::path& file) : file_(file) {}

  [[noreturn]] void bad(const std::string& what) const { fail(file_, what); }

  const json& member(const json& parent, const char* key, const std::string& where) const {
    auto it = parent.find(key);
    if (it == parent.end()) bad("\"" + where + "\" is missing");
    return *it;
  }
  double number(const json& v, const std::string& where) const {
    if (!v.is_number() || !std::isfinite(v.get<double>())) bad("\"" + where + "\" is not a finite number");
    return v.get<double>();
  }
  uint64_t integer(const json& v, const std::string& where, uint64_t max) const {
    uint64_t value = 0;
    if (v.is_number_unsigned()) {
      value = v.get<uint64_t>();
    } else if (v.is_number_integer() && v.get<int64_t>() >= 0) {
      value = uint64_t(v.get<int64_t>());
    } else if (v.is_number_float() && v.get<double>() >= 0 && v.get<double>() <= 9.0e18 &&
               std::floor(v.get<double>()) == v.get<double>()) {
      value = uint64_t(v.get<double>());
    } else {
      bad("\"" + where + "\" is not a non-negative integer");
    }
    if (value > max)
      bad(strFormat("\"%s\" is %llu, more than %llu", where.c_str(), static_cast<unsigned long long>(value),
                    static_cast<unsigned long long>(max)));
    return value;
  }
  glm::dvec3 vec3(const json& v, const std::string& where) const {
    if (!v.is_array() || v.size() != 3) bad("\"" + where + "\" is not an array of 3 numbers");
    return {number(v[0], where), number(v[1], where), number(v[2], where)};
  }
  std::string text(const json& parent, const char* key) const {
    auto it = parent.find(key);
    return it != parent.end() && it->is_string() ? it->get<std::string>() : std::string();
  }

private:
  std::filesystem::path file_;
};

// Numbers of an optional min/max array; empty when absent or not all finite numbers.
std::vector<double> numbers(const json& parent, const char* key) {
  std::vector<double> out;
  auto it = parent.find(key);
  if (it == parent.end() || !it->is_array() || it->size() > 64) return out;
  for (const json& v : *it) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) return {};
    out.push_back(v.get<double>());
  }
  return out;
}

Attribute readAttribute(const Reader& r, const json& j, size_t i) {
  const std::string where = "attributes[" + std::to_string(i) + "]";
  if (!j.is_object()) r.bad("\"" + where + "\" is not an object");
  Attribute a;
  const json& name = r.member(j, "name", where + ".name");
  if (!name.is_string() || name.get<std::string>().empty()) r.bad("\"" + where + ".name\" is not a name");
  a.name = name.get<std::string>();
  a.description = r.text(j, "description");
  const std::string at = "attribute \"" + a.name + "\" ";
  a.size = int(r.integer(r.member(j, "size", at + "size"), at + "size", kMaxAttributeSize));
  if (a.size == 0) r.bad(at + "has size 0");
  a.numElements =
      int(r.integer(r.member(j, "numElements", at + "numElements"), at + "numElements", kMaxAttributeSize));
  a.elementSize =
      int(r.integer(r.member(j, "elementSize", at + "elementSize"), at + "elementSize", kMaxAttributeSize));
  const json& type = r.member(j, "type", at + "type");
  if (!type.is_string()) r.bad("\"" + at + "type\" is not a string");
  a.type = type.get<std::string>();
  a.min = numbers(j, "min");
  a.max = numbers(j, "max");
  return a;
}

// The cube the viewer halves into children; PotreeConverter writes min + edge per axis, so the edges may
// differ by rounding only.
Bounds readCube(const Reader& r, const json& root) {
  const json& box = r.member(root, "boundingBox", "boundingBox");
  if (!box.is_object()) r.bad("\"boundingBox\" is not an object");
  Bounds cube;
  cube.min = r.vec3(r.member(box, "min", "boundingBox.min"), "boundingBox.min");
  cube.max = r.vec3(r.member(box, "max", "boundingBox.max"), "boundingBox.max");
  const glm::dvec3 edges = cube.max - cube.min;
  const double edge = std::max({edges.x, edges.y, edges.z});
  if (!(edges.x >= 0 && edges.y >= 0 && edges.z >= 0) || !std::isfinite(edge))
    r.bad("\"boundingBox\" has its min above its max");
  const double tolerance = 1e-6 * std::max(edge, 1e-300);
  if (edge - edges.x > tolerance || edge - edges.y > tolerance || edge - edges.z > tolerance)
    r.bad(strFormat("\"boundingBox\" is not a cube (edges %g, %g, %g)", edges.x, edges.y, edges.z));
  cube.max = cube.min + glm::dvec3(edge);
  return cube;
}

void readHierarchy(const Reader& r, const json& root, Metadata& m) {
  const json& h = r.member(root, "hierarchy", "hierarchy");
  if (!h.is_object()) r.bad("\"hierarchy\" is not an object");
  m.firstChunkSize = r.integer(r.member(h, "firstChunkSize", "hierarchy.firstChunkSize"),
                               "hierarchy.firstChunkSize", uint64_t(INT64_MAX));
  if (m.firstChunkSize == 0 || m.firstChunkSize % kRecordBytes != 0)
    r.bad(strFormat("\"hierarchy.firstChunkSize\" is %llu, not a positive multiple of %llu",
                    static_cast<unsigned long long>(m.firstChunkSize),
                    static_cast<unsigned long long>(kRecordBytes)));
  m.stepSize = int(r.integer(r.member(h, "stepSize", "hierarchy.stepSize"), "hierarchy.stepSize", kMaxLevel));
  if (m.stepSize == 0) r.bad("\"hierarchy.stepSize\" is 0");
  m.depth = int(r.integer(r.member(h, "depth", "hierarchy.depth"), "hierarchy.depth", kMaxLevel));
}

void readAttributes(const Reader& r, const json& root, Metadata& m) {
  const json& list = r.member(root, "attributes", "attributes");
  if (!list.is_array() || list.empty()) r.bad("\"attributes\" is not a list of attributes");
  if (list.size() > kMaxAttributes) r.bad(strFormat("%zu attributes is too many", list.size()));
  std::vector<Attribute> attributes;
  for (size_t i = 0; i < list.size(); ++i)
    attributes.push_back(readAttribute(r, list[i], i));
  m.layout = makeLayout(std::move(attributes));
  const Attribute* position = nullptr;
  for (const Attribute& a : m.layout.attributes)
    if (a.field == Field::Position) position = &a;
  if (!position) r.bad("no \"position\" attribute of 3 int32 values");
  // Tight bounds: the position attribute's range, in world coordinates as PotreeConverter writes it.
  if (position->min.size() == 3 && position->max.size() == 3) {
    Bounds b;
    b.min = {position->min[0], position->min[1], position->min[2]};
    b.max = {position->max[0], position->max[1], position->max[2]};
    if (!b.empty()) m.bounds = b;
  }
}

// The "lasAttributes" block of pointrast's octrees (see metadataJson); a block that does not describe the
// attributes listed is ignored (the points are read without tails).
void readTail(const json& root, Layout& layout) {
  auto it = root.find("lasAttributes");
  if (it == root.end() || !it->is_object()) return;
  const json& j = *it;
  auto flag = [&](const char* key) {
    auto f = j.find(key);
    return f != j.end() && f->is_boolean() && f->get<bool>();
  };
  TailFormat t;
  PointAttributes& a = t.attributes;
  a.gpsTime = flag("gpsTime");
  a.scanAngle = flag("scanAngle");
  a.extendedScanAngle = flag("extendedScanAngle");
  a.nir = flag("nir");
  a.numberOfReturns = flag("numberOfReturns");
  a.flags = flag("flags");
  a.userData = flag("userData");
  auto extra = j.find("extraBytes");
  if (extra != j.end() && extra->is_number_unsigned() && extra->get<uint64_t>() <= 0xFFFF)
    a.extraBytes = static_cast<uint16_t>(extra->get<uint64_t>());
  auto format = j.find("pointFormat");
  if (format != j.end() && format->is_number_integer() && format->get<int64_t>() >= 0 &&
      format->get<int64_t>() <= 10)
    t.lasPointFormat = static_cast<int>(format->get<int64_t>());
  auto hex = j.find("extraBytesDescriptors");
  if (hex != j.end() && hex->is_string()) {
    const std::string& h = hex->get_ref<const std::string&>();
    auto digit = [](char c) {
      return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
    };
    if (h.size() % 2 != 0) return;
    for (size_t i = 0; i < h.size(); i += 2) {
      const int hi = digit(h[i]), lo = digit(h[i + 1]);
      if (hi < 0 || lo < 0) return;
      t.extraBytesDescriptors.push_back(static_cast<uint8_t>(hi << 4 | lo));
    }
  }
  t.layout = attributeLayout(a);
  attachTail(layout, t);
}

// The tail of an octree PotreeConverter wrote: the LAS attributes it names (potree_attributes.h) in their
// tail fields, every other attribute past the record fields as an extra bytes field of its name and type
// (a descriptor made up for it), so that a pick shows every attribute the points hold. The point format
// stays unknown: an export writes the record fields alone. Attributes that do not fit (a name longer than
// a descriptor holds, a field of more than 255 bytes) leave the points without a tail, as before.
void inferTail(Layout& layout) {
  static const char* const kFlags[] = {"classification flags", "scanner channel", "scan direction flag",
                                       "edge of flight line"};
  auto find = [&](const char* name, const char* type, int size) -> const Attribute* {
    for (const Attribute& a : layout.attributes)
      if (a.field == Field::Other && a.name == name && a.type == type && a.size == size) return &a;
    return nullptr;
  };
  TailFormat t;
  PointAttributes& a = t.attributes;
  std::vector<const Attribute*> known;
  auto take = [&](bool& flag, const char* name, const char* type, int size) {
    if (const Attribute* at = find(name, type, size)) {
      flag = true;
      known.push_back(at);
    }
  };
  take(a.gpsTime, "gps-time", "double", 8);
  take(a.numberOfReturns, "number of returns", "uint8", 1);
  take(a.userData, "user data", "uint8", 1);
  take(a.nir, "nir", "uint16", 2);
  take(a.scanAngle, "scan angle rank", "uint8", 1);
  if (!a.scanAngle) {
    take(a.scanAngle, "scan angle", "int16", 2);
    a.extendedScanAngle = a.scanAngle;
  }
  // The flags byte only where all four of its fields are there; one alone is shown as a field of its own.
  std::vector<const Attribute*> flags;
  for (const char* name : kFlags)
    if (const Attribute* at = find(name, "uint8", 1)) flags.push_back(at);
  if (flags.size() == 4) {
    a.flags = true;
    known.insert(known.end(), flags.begin(), flags.end());
  }
  static const char* const kTypes[] = {"uint8", "int8",   "uint16", "int16", "uint32",
                                       "int32", "uint64", "int64",  "float", "double"};
  uint32_t extra = 0;
  for (const Attribute& at : layout.attributes) {
    if (at.field != Field::Other || std::find(known.begin(), known.end(), &at) != known.end()) continue;
    if (at.name.empty() || at.name.size() > 32 || at.size <= 0 || at.size > 255) return;
    int dataType = 0;
    for (int k = 0; k < 10; ++k)
      if (at.type == kTypes[k] && at.numElements >= 1 && at.numElements <= 3 &&
          at.size == at.numElements * typeSize(at.type))
        dataType = k + 1 + 10 * (at.numElements - 1);
    // R15 Table 24: data type at byte 2, options (for type 0 the byte count) at 3, the name at 4.
    uint8_t d[192] = {};
    d[2] = static_cast<uint8_t>(dataType);
    d[3] = static_cast<uint8_t>(dataType == 0 ? at.size : 0);
    std::memcpy(d + 4, at.name.data(), at.name.size());
    t.extraBytesDescriptors.insert(t.extraBytesDescriptors.end(), d, d + sizeof d);
    extra += uint32_t(at.size);
  }
  if (extra > 0xFFFF) return;
  a.extraBytes = static_cast<uint16_t>(extra);
  if (!a.any()) return;
  t.layout = attributeLayout(a);
  attachTail(layout, t);
}

json jsonVec(const glm::dvec3& v) {
  return json::array({v.x, v.y, v.z});
}

} // namespace

const char* encodingName(PotreeEncoding encoding) {
  return encoding == PotreeEncoding::Brotli ? "BROTLI" : "DEFAULT";
}

int encodedBytes(const Attribute& attribute, PotreeEncoding encoding) {
  if (encoding == PotreeEncoding::Brotli) {
    if (attribute.field == Field::Position) return 16; // two 48-bit Morton codes in 64-bit words
    if (attribute.field == Field::Rgb) return 8;       // one 48-bit Morton code in a 64-bit word
  }
  return attribute.size;
}

Layout makeLayout(std::vector<Attribute> attributes) {
  Layout layout;
  bool seen[7] = {};
  for (Attribute& a : attributes) {
    a.field = classify(a);
    // The first attribute of a field fills it; a repeated one is skipped like any other.
    if (seen[int(a.field)] && a.field != Field::Other) a.field = Field::Other;
    seen[int(a.field)] = true;
    layout.defaultStride += uint64_t(a.size);
    layout.brotliStride += uint64_t(encodedBytes(a, PotreeEncoding::Brotli));
    switch (a.field) {
    case Field::Rgb:
      layout.fields.color = true;
      for (double v : a.max)
        layout.fields.colorMax =
            std::max<uint16_t>(layout.fields.colorMax, uint16_t(std::clamp(v, 0.0, 65535.0)));
      break;
    case Field::Intensity:
      layout.fields.intensity = true;
      break;
    case Field::ReturnNumber:
      layout.fields.returnNumber = true;
      break;
    case Field::Classification:
      layout.fields.classification = true;
      break;
    case Field::PointSourceId:
      layout.fields.pointSourceId = true;
      break;
    case Field::Position:
    case Field::Other:
      break;
    }
  }
  layout.attributes = std::move(attributes);
  return layout;
}

namespace {

// The tail's attributes as Potree names them (potree_attributes.h); extra bytes fields from the
// descriptors, or one undocumented field where they do not parse.
std::vector<TailAttribute> tailList(const TailFormat& tail) {
  std::vector<ExtraBytesField> extra;
  try {
    extra = parseExtraBytes(tail.extraBytesDescriptors, tail.attributes.extraBytes, "");
  } catch (const InputError&) {
    extra = parseExtraBytes({}, tail.attributes.extraBytes, "");
  }
  return tailAttributes(tail.attributes, tail.layout, extra);
}

} // namespace

Layout writerLayout(const RecordFields& fields, const TailFormat& tail) {
  std::vector<Attribute> list{makeAttribute("position", "int32", 3)};
  if (fields.intensity) list.push_back(makeAttribute("intensity", "uint16", 1));
  if (fields.returnNumber) list.push_back(makeAttribute("return number", "uint8", 1));
  if (fields.classification) list.push_back(makeAttribute("classification", "uint8", 1));
  if (fields.pointSourceId) list.push_back(makeAttribute("point source id", "uint16", 1));
  if (fields.color) list.push_back(makeAttribute("rgb", "uint16", 3));
  if (tail.bytes() > 0)
    for (const TailAttribute& t : tailList(tail)) {
      Attribute a;
      a.name = t.name;
      a.description = t.description;
      a.type = t.type;
      a.size = t.size;
      a.numElements = t.numElements;
      a.elementSize = t.elementSize;
      list.push_back(std::move(a));
    }
  Layout layout = makeLayout(std::move(list));
  attachTail(layout, tail);
  return layout;
}

bool attachTail(Layout& layout, const TailFormat& tail) {
  layout.tail = {};
  layout.tailSlots.clear();
  if (tail.bytes() == 0) {
    layout.tail = tail; // the point format alone
    return true;
  }
  std::vector<TailSlot> slots;
  for (const TailAttribute& t : tailList(tail)) {
    int at = 0;
    bool found = false;
    for (const Attribute& a : layout.attributes) {
      if (a.name == t.name && a.field == Field::Other) {
        if (a.size != t.size) return false;
        found = true;
        break;
      }
      at += a.size;
    }
    if (!found) return false;
    slots.push_back({at, t.tailOffset, t.size, t.shift, t.bits});
  }
  layout.tail = tail;
  layout.tailSlots = std::move(slots);
  return true;
}

std::string metadataJson(const Metadata& m) {
  nlohmann::ordered_json j;
  j["version"] = "2.0";
  j["name"] = m.name;
  j["description"] = m.description;
  j["points"] = m.points;
  j["projection"] = m.projection;
  j["hierarchy"] = {{"firstChunkSize", m.firstChunkSize}, {"stepSize", m.stepSize}, {"depth", m.depth}};
  j["offset"] = jsonVec(m.offset);
  j["scale"] = jsonVec(m.scale);
  j["spacing"] = m.spacing;
  j["boundingBox"] = {{"min", jsonVec(m.cube.min)}, {"max", jsonVec(m.cube.max)}};
  j["encoding"] = encodingName(m.encoding);
  j["attributes"] = nlohmann::ordered_json::array();
  for (const Attribute& a : m.layout.attributes) {
    nlohmann::ordered_json attribute;
    attribute["name"] = a.name;
    attribute["description"] = a.description;
    attribute["size"] = a.size;
    attribute["numElements"] = a.numElements;
    attribute["elementSize"] = a.elementSize;
    attribute["type"] = a.type;
    attribute["min"] = a.min;
    attribute["max"] = a.max;
    j["attributes"].push_back(attribute);
  }
  // Not a Potree field (the viewer ignores it): tells a reader that the integers are exact.
  j["generator"] = m.generator;
  // Not a Potree field either: what the tail attributes hold, and the LAS point format and extra bytes
  // descriptions they came from, so an export writes the records back as they were.
  const TailFormat& t = m.layout.tail;
  if (t.bytes() > 0 || t.lasPointFormat >= 0) {
    static const char kHex[] = "0123456789abcdef";
    std::string hex;
    for (uint8_t b : t.extraBytesDescriptors) {
      hex += kHex[b >> 4];
      hex += kHex[b & 15];
    }
    const PointAttributes& a = t.attributes;
    j["lasAttributes"] = {{"pointFormat", t.lasPointFormat},
                          {"gpsTime", a.gpsTime},
                          {"scanAngle", a.scanAngle},
                          {"extendedScanAngle", a.extendedScanAngle},
                          {"nir", a.nir},
                          {"numberOfReturns", a.numberOfReturns},
                          {"flags", a.flags},
                          {"userData", a.userData},
                          {"extraBytes", a.extraBytes},
                          {"extraBytesDescriptors", hex}};
  }
  // A name taken from a file name in another encoding than UTF-8 is replaced, not an exception after the
  // whole build.
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

Metadata parseMetadata(const std::string& text, const std::filesystem::path& file) {
  const Reader r(file);
  const json root = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded()) r.bad("not valid JSON");
  if (!root.is_object()) r.bad("not a JSON object");
  auto version = root.find("version");
  if (version == root.end() || !version->is_string())
    r.bad("no \"version\": not the metadata.json of a Potree 2.0 octree");
  if (version->get<std::string>() != "2.0")
    r.bad("version \"" + version->get<std::string>() + "\": pointrast reads Potree 2.0 octrees");

  Metadata m;
  m.name = r.text(root, "name");
  m.description = r.text(root, "description");
  m.projection = r.text(root, "projection");
  m.generator = r.text(root, "generator");
  const std::string encoding = root.contains("encoding") ? r.text(root, "encoding") : "DEFAULT";
  if (encoding == "DEFAULT")
    m.encoding = PotreeEncoding::Default;
  else if (encoding == "BROTLI")
    m.encoding = PotreeEncoding::Brotli;
  else
    r.bad("\"encoding\" is \"" + encoding + "\", not DEFAULT or BROTLI");
  m.points = r.integer(r.member(root, "points", "points"), "points", uint64_t(INT64_MAX));
  readHierarchy(r, root, m);
  m.offset = r.vec3(r.member(root, "offset", "offset"), "offset");
  m.scale = r.vec3(r.member(root, "scale", "scale"), "scale");
  if (!(m.scale.x > 0 && m.scale.y > 0 && m.scale.z > 0)) r.bad("\"scale\" is not positive");
  m.spacing = r.number(r.member(root, "spacing", "spacing"), "spacing");
  if (m.spacing < 0) r.bad("\"spacing\" is negative");
  m.cube = readCube(r, root);
  readAttributes(r, root, m);
  if (m.fromPointrast())
    readTail(root, m.layout);
  else
    inferTail(m.layout);
  return m;
}

} // namespace pointrast::io::potree
