#include "view/web/protocol.h"

#include <cmath>
#include <cstring>
#include <initializer_list>

#include <nlohmann/json.hpp>

#include "base/error.h"
#include "cloud/attribute_colors.h"
#include "shared.h"

namespace pointrast::view::web {

namespace {

using Json = nlohmann::json;

struct KeyName {
  Key key;
  const char* name;
};
constexpr KeyName kKeyNames[] = {
    {Key::Forward, "Forward"},
    {Key::Back, "Back"},
    {Key::Left, "Left"},
    {Key::Right, "Right"},
    {Key::Down, "Down"},
    {Key::Up, "Up"},
    {Key::FrameAll, "FrameAll"},
    {Key::Keyframe, "Keyframe"},
    {Key::TogglePanel, "TogglePanel"},
    {Key::PrintCamera, "PrintCamera"},
    {Key::Screenshot, "Screenshot"},
    {Key::ViewTop, "ViewTop"},
    {Key::ViewBottom, "ViewBottom"},
    {Key::ViewFront, "ViewFront"},
    {Key::ViewBack, "ViewBack"},
    {Key::ViewLeft, "ViewLeft"},
    {Key::ViewRight, "ViewRight"},
    {Key::ViewIso, "ViewIso"},
};

struct TypeName {
  MessageType type;
  const char* name;
  std::initializer_list<const char*> fields; // besides "t" and "seq"
};
const TypeName kTypes[] = {
    {MessageType::Resize, "resize", {"w", "h"}},
    {MessageType::Down, "down", {"b", "x", "y"}},
    {MessageType::Move, "move", {"x", "y"}},
    {MessageType::Up, "up", {"b", "x", "y"}},
    {MessageType::DoubleClick, "dblclick", {"x", "y"}},
    {MessageType::Wheel, "wheel", {"x", "y", "steps"}},
    {MessageType::Key, "key", {"key", "down", "shift"}},
    {MessageType::Settings,
     "settings",
     {"method", "background", "depth", "color", "colorRange", "pointSize", "pointSizeMax", "pointShape",
      "pointSizeMode", "dilate", "edlStrength", "edlRadius", "minNodePx", "pointBudget", "gpuMemory", "stereo", "crossed", "ipd", "foveated", "foveaRadius",
      "foveaPeriphery", "clipBox", "clipMode"}},
    {MessageType::Options, "options", {"supersample", "keyframeSeconds"}},
    {MessageType::Stream, "stream", {"motionScale", "quality", "motionQuality"}},
    {MessageType::Action, "action", {"name"}},
    {MessageType::Ack, "ack", {"frame"}},
    {MessageType::PickPoint, "pickpoint", {"x", "y", "measure"}},
    {MessageType::Measure, "measure", {"op", "index", "x", "y", "tx", "ty"}},
};

// Thrown inside the parser only; parseClientMessage turns it into the refusal's sentence.
struct Refused {
  std::string why;
};

[[noreturn]] void refuse(std::string why) {
  throw Refused{std::move(why)};
}

const Json& field(const Json& j, const char* name) {
  auto it = j.find(name);
  if (it == j.end()) refuse(std::string("missing \"") + name + "\"");
  return *it;
}

double number(const Json& j, const char* name, double lo, double hi) {
  const Json& v = field(j, name);
  if (!v.is_number()) refuse(std::string("\"") + name + "\" must be a number");
  double d = v.get<double>();
  if (!std::isfinite(d) || d < lo || d > hi) refuse(std::string("\"") + name + "\" is out of range");
  return d;
}

uint64_t integer(const Json& j, const char* name, uint64_t lo, uint64_t hi) {
  const Json& v = field(j, name);
  if (!v.is_number_unsigned()) refuse(std::string("\"") + name + "\" must be a non-negative integer");
  uint64_t n = v.get<uint64_t>();
  if (n < lo || n > hi) refuse(std::string("\"") + name + "\" is out of range");
  return n;
}

bool boolean(const Json& j, const char* name) {
  const Json& v = field(j, name);
  if (!v.is_boolean()) refuse(std::string("\"") + name + "\" must be true or false");
  return v.get<bool>();
}

const std::string& string(const Json& j, const char* name) {
  const Json& v = field(j, name);
  if (!v.is_string()) refuse(std::string("\"") + name + "\" must be a string");
  return v.get_ref<const std::string&>();
}

glm::dvec2 position(const Json& j) {
  return {number(j, "x", -kPositionMargin, 1 + kPositionMargin),
          number(j, "y", -kPositionMargin, 1 + kPositionMargin)};
}

MouseButton button(const Json& j) {
  switch (integer(j, "b", 0, 2)) {
  case 0:
    return MouseButton::Left;
  case 1:
    return MouseButton::Middle;
  default:
    return MouseButton::Right;
  }
}

// One of `names` (the choices of a string field).
template <typename T, size_t N>
T choice(const Json& j, const char* name, const std::pair<const char*, T> (&names)[N]) {
  const std::string& text = string(j, name);
  for (const auto& [n, value] : names)
    if (text == n) return value;
  refuse(std::string("unknown \"") + name + "\"");
}

constexpr std::pair<const char*, DepthMode> kDepths[] = {{"float", DepthMode::Float},
                                                         {"int40", DepthMode::Int40}};
constexpr std::pair<const char*, PointShape> kShapes[] = {{"square", PointShape::Square},
                                                          {"disc", PointShape::Disc}};
constexpr std::pair<const char*, PointSizeMode> kSizeModes[] = {{"fixed", PointSizeMode::Fixed},
                                                                {"attenuated", PointSizeMode::Attenuated}};

void settings(const Json& j, std::span<const Method> methods, ClientMessage& m) {
  SettingsChange& c = m.settings;
  if (j.contains("clipBox")) {
    const Json& v = j["clipBox"];
    c.clip = true;
    if (!v.is_null()) {
      if (!v.is_array() || v.size() != 6) refuse("\"clipBox\" must be [x0, y0, z0, x1, y1, z1] or null");
      ClipBox b;
      for (int i = 0; i < 6; ++i) {
        if (!v[size_t(i)].is_number() || !std::isfinite(v[size_t(i)].get<double>()))
          refuse("\"clipBox\" takes finite numbers");
        (i < 3 ? b.min : b.max)[i % 3] = v[size_t(i)].get<double>();
      }
      if (!(b.min.x <= b.max.x && b.min.y <= b.max.y && b.min.z <= b.max.z))
        refuse("\"clipBox\" is [min corner, max corner]");
      c.clipBox = b;
    }
  }
  if (j.contains("clipMode")) {
    const std::string& mode = string(j, "clipMode");
    if (mode == "inside")
      c.clipMode = ClipMode::Inside;
    else if (mode == "outside")
      c.clipMode = ClipMode::Outside;
    else
      refuse("\"clipMode\" takes inside or outside");
  }
  if (j.contains("method")) {
    const std::string& name = string(j, "method");
    for (Method method : methods)
      if (name == methodName(method)) c.method = method;
    if (!c.method) refuse("\"method\" is not a method this device runs");
  }
  if (j.contains("background")) {
    const Json& v = j["background"];
    if (!v.is_array() || v.size() != 3) refuse("\"background\" must be [r, g, b]");
    uint32_t rgba = 0xFF000000u;
    for (int i = 0; i < 3; ++i) {
      if (!v[i].is_number_unsigned() || v[i].get<uint64_t>() > 255) refuse("\"background\" takes 0..255");
      rgba |= uint32_t(v[i].get<uint64_t>()) << (8 * i);
    }
    c.background = rgba;
  }
  if (j.contains("depth")) c.depth = choice(j, "depth", kDepths);
  if (j.contains("color")) {
    c.color = true;
    const std::string& name = string(j, "color");
    if (name != "auto") {
      for (auto source : {DisplayColorMode::Source::Rgb, DisplayColorMode::Source::Intensity,
                          DisplayColorMode::Source::Elevation, DisplayColorMode::Source::Classification,
                          DisplayColorMode::Source::ReturnNumber, DisplayColorMode::Source::PointSource})
        if (name == colorSourceName(source)) c.colorSource = source;
      if (!c.colorSource) refuse("unknown \"color\"");
    }
  }
  if (j.contains("colorRange")) {
    c.range = true;
    const Json& v = j["colorRange"];
    if (!v.is_null()) {
      if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
        refuse("\"colorRange\" must be [lo, hi] or null");
      double lo = v[0].get<double>(), hi = v[1].get<double>();
      if (!std::isfinite(lo) || !std::isfinite(hi) || std::abs(lo) > 1e12 || std::abs(hi) > 1e12 ||
          !(lo < hi))
        refuse("\"colorRange\" must be finite with lo < hi");
      c.colorRange = ColorRange{lo, hi};
    }
  }
  const double maxSize = shared::kMaxPointSize;
  if (j.contains("pointSize")) c.pointSize = float(number(j, "pointSize", 1, maxSize));
  if (j.contains("pointSizeMax")) c.pointSizeMax = float(number(j, "pointSizeMax", 1, maxSize));
  if (j.contains("pointShape")) c.pointShape = choice(j, "pointShape", kShapes);
  if (j.contains("pointSizeMode")) c.pointSizeMode = choice(j, "pointSizeMode", kSizeModes);
  if (j.contains("dilate")) c.dilate = uint32_t(integer(j, "dilate", 0, shared::kMaxDilateRadius));
  if (j.contains("edlStrength")) c.edlStrength = float(number(j, "edlStrength", 0, kMaxEdlStrength));
  if (j.contains("edlRadius")) {
    c.edlRadius = float(number(j, "edlRadius", 0, 16));
    if (!(*c.edlRadius > 0)) refuse("\"edlRadius\" is out of range");
  }
  if (j.contains("minNodePx")) c.minNodePx = number(j, "minNodePx", 0, kMaxMinNodePx);
  if (j.contains("pointBudget")) c.pointBudget = integer(j, "pointBudget", 0, kMaxPointBudget);
  if (j.contains("gpuMemory")) c.gpuMemory = integer(j, "gpuMemory", 0, kMaxGpuMemory);
  if (j.contains("stereo")) c.stereo = boolean(j, "stereo");
  if (j.contains("crossed")) c.crossed = boolean(j, "crossed");
  if (j.contains("ipd")) c.ipd = number(j, "ipd", 0, 1e12);
  if (j.contains("foveated")) c.foveated = boolean(j, "foveated");
  if (j.contains("foveaRadius")) c.foveaRadius = number(j, "foveaRadius", 0, 1);
  if (j.contains("foveaPeriphery")) c.foveaPeriphery = number(j, "foveaPeriphery", 1, kMaxFoveaPeriphery);
  // Only "t" and "seq" besides: a message that names no setting changes nothing.
  if (j.size() <= (j.contains("seq") ? 2u : 1u)) refuse("\"settings\" changes nothing");
}

void options(const Json& j, ClientMessage& m) {
  if (j.contains("supersample")) {
    uint64_t s = integer(j, "supersample", 1, 4);
    if (s == 3) refuse("\"supersample\" takes 1, 2 or 4");
    m.supersample = uint32_t(s);
  }
  if (j.contains("keyframeSeconds")) m.keyframeSeconds = number(j, "keyframeSeconds", 0.1, 60);
  if (!m.supersample && !m.keyframeSeconds) refuse("\"options\" changes nothing");
}

void stream(const Json& j, ClientMessage& m) {
  if (j.contains("motionScale")) m.motionScale = number(j, "motionScale", 0.25, 1);
  if (j.contains("quality")) m.quality = int(integer(j, "quality", 10, 100));
  if (j.contains("motionQuality")) m.motionQuality = int(integer(j, "motionQuality", 10, 100));
  if (!m.motionScale && !m.quality && !m.motionQuality) refuse("\"stream\" changes nothing");
}

ClientMessage parse(const Json& j, std::span<const Method> methods) {
  if (!j.is_object()) refuse("a message must be a JSON object");
  const std::string& t = string(j, "t");
  const TypeName* type = nullptr;
  for (const TypeName& candidate : kTypes)
    if (t == candidate.name) type = &candidate;
  if (!type) refuse("unknown message type");
  for (const auto& [name, value] : j.items()) {
    bool known = name == "t" || name == "seq";
    for (const char* f : type->fields)
      known = known || name == f;
    if (!known) refuse("unknown field \"" + name.substr(0, 32) + "\"");
  }
  ClientMessage m;
  m.type = type->type;
  if (j.contains("seq")) m.seq = uint32_t(integer(j, "seq", 0, UINT32_MAX));
  switch (m.type) {
  case MessageType::Resize:
    m.width = uint32_t(integer(j, "w", 1, kMaxCanvasSide));
    m.height = uint32_t(integer(j, "h", 1, kMaxCanvasSide));
    break;
  case MessageType::Down:
  case MessageType::Up:
    m.button = button(j);
    m.position = position(j);
    break;
  case MessageType::Move:
  case MessageType::DoubleClick:
    m.position = position(j);
    break;
  case MessageType::Wheel:
    m.position = position(j);
    m.steps = number(j, "steps", -kMaxWheelSteps, kMaxWheelSteps);
    break;
  case MessageType::Key: {
    std::optional<Key> key = keyFromName(string(j, "key"));
    if (!key) refuse("unknown key");
    m.key = *key;
    m.down = boolean(j, "down");
    m.shift = j.contains("shift") && boolean(j, "shift");
    break;
  }
  case MessageType::Settings:
    settings(j, methods, m);
    break;
  case MessageType::Options:
    options(j, m);
    break;
  case MessageType::Stream:
    stream(j, m);
    break;
  case MessageType::Action: {
    const std::string& name = string(j, "name");
    if (name == "clearKeyframes")
      m.action = ClientAction::ClearKeyframes;
    else if (name == "downloadPath")
      m.action = ClientAction::DownloadPath;
    else
      refuse("unknown action");
    break;
  }
  case MessageType::Ack:
    m.frame = uint32_t(integer(j, "frame", 0, UINT32_MAX));
    break;
  case MessageType::PickPoint:
    m.position = position(j);
    if (j.contains("measure")) {
      const std::string& kind = string(j, "measure");
      if (kind == "distance")
        m.measure = AnnotationKind::Distance;
      else if (kind == "height")
        m.measure = AnnotationKind::Height;
      else if (kind == "area")
        m.measure = AnnotationKind::Area;
      else
        refuse("unknown measurement");
    }
    break;
  case MessageType::Measure: {
    const std::string& op = string(j, "op");
    if (op == "finish")
      m.measureOp = MeasureOp::Finish;
    else if (op == "delete")
      m.measureOp = MeasureOp::Delete;
    else if (op == "clear")
      m.measureOp = MeasureOp::Clear;
    else if (op == "download")
      m.measureOp = MeasureOp::Download;
    else if (op == "move")
      m.measureOp = MeasureOp::Move;
    else
      refuse("unknown measure operation");
    if (m.measureOp == MeasureOp::Delete) m.index = uint32_t(integer(j, "index", 0, UINT32_MAX));
    if (m.measureOp == MeasureOp::Move) {
      m.position = position(j);
      m.target = {number(j, "tx", -kPositionMargin, 1 + kPositionMargin),
                  number(j, "ty", -kPositionMargin, 1 + kPositionMargin)};
    }
    break;
  }
  }
  return m;
}

template <typename T> void put(uint8_t*& out, T value) {
  std::memcpy(out, &value, sizeof value); // the wire is little-endian, as is every machine we build for
  out += sizeof value;
}

template <typename T> T get(const uint8_t*& in) {
  T value;
  std::memcpy(&value, in, sizeof value);
  in += sizeof value;
  return value;
}

} // namespace

ViewSettings applySettings(const ViewSettings& settings, const SettingsChange& c) {
  ViewSettings s = settings;
  if (c.method) s.method = *c.method;
  if (c.background) s.background = *c.background;
  if (c.depth) s.depth = *c.depth;
  if (c.color) {
    if (s.colorSource != c.colorSource) s.colorRange.reset();
    s.colorSource = c.colorSource;
  }
  if (c.range) s.colorRange = c.colorRange;
  if (c.pointSize) s.post.pointSize = *c.pointSize;
  if (c.pointSizeMax) s.post.maxPointSize = *c.pointSizeMax;
  if (c.pointShape) s.post.shape = *c.pointShape;
  if (c.pointSizeMode) s.post.sizeMode = *c.pointSizeMode;
  if (c.dilate) s.post.dilate = *c.dilate;
  if (c.edlStrength) s.post.edlStrength = *c.edlStrength;
  if (c.edlRadius) s.post.edlRadius = *c.edlRadius;
  if (c.minNodePx) s.minNodePx = *c.minNodePx;
  if (c.pointBudget) s.pointBudget = *c.pointBudget;
  if (c.gpuMemory) s.gpuMemory = *c.gpuMemory;
  if (c.stereo) s.stereo = *c.stereo;
  if (c.crossed) s.eyes.crossed = *c.crossed;
  if (c.ipd) s.eyes.separation = *c.ipd;
  if (c.foveated) s.foveation.enabled = *c.foveated;
  if (c.foveaRadius) s.foveation.radius = *c.foveaRadius;
  if (c.foveaPeriphery) s.foveation.periphery = *c.foveaPeriphery;
  if (c.clip) {
    s.filter.boxes.clear();
    if (c.clipBox) s.filter.boxes.push_back(*c.clipBox);
  }
  if (c.clipMode) s.filter.clipMode = *c.clipMode;
  validateSettings(s);
  return s;
}

std::optional<Key> keyFromName(std::string_view name) {
  for (const KeyName& k : kKeyNames)
    if (name == k.name) return k.key;
  return std::nullopt;
}

const char* keyName(Key key) {
  for (const KeyName& k : kKeyNames)
    if (key == k.key) return k.name;
  return "?";
}

std::variant<ClientMessage, std::string> parseClientMessage(std::string_view text,
                                                            std::span<const Method> methods) {
  if (text.size() > kMaxMessageBytes) return std::string("message too long");
  // The JSON parser stops at a NUL byte as at the end of the text: what follows it would pass unread. JSON
  // has no raw NUL anywhere (inside a string it is escaped).
  if (text.find('\0') != std::string_view::npos) return std::string("a NUL byte");
  // Invalid UTF-8 and nesting deeper than the 1 KiB allow fail the parse like any other malformed text.
  Json j = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return std::string("not JSON");
  try {
    return parse(j, methods);
  } catch (const Refused& r) {
    return r.why;
  }
}

void writeFrameHeader(const FrameHeader& h, uint8_t* out) {
  put(out, h.magic);
  put(out, h.frame);
  put(out, h.seq);
  put(out, h.width);
  put(out, h.height);
  put(out, h.viewWidth);
  put(out, h.viewHeight);
  put(out, h.quality);
  put(out, h.flags);
  put(out, uint16_t(0));
  put(out, h.renderMs);
  put(out, h.encodeMs);
}

FrameHeader readFrameHeader(const uint8_t* in) {
  FrameHeader h;
  h.magic = get<uint32_t>(in);
  h.frame = get<uint32_t>(in);
  h.seq = get<uint32_t>(in);
  h.width = get<uint16_t>(in);
  h.height = get<uint16_t>(in);
  h.viewWidth = get<uint16_t>(in);
  h.viewHeight = get<uint16_t>(in);
  h.quality = get<uint8_t>(in);
  h.flags = get<uint8_t>(in);
  get<uint16_t>(in);
  h.renderMs = get<float>(in);
  h.encodeMs = get<float>(in);
  return h;
}

} // namespace pointrast::view::web
