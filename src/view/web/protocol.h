// The browser viewer's wire protocol. A client sends small JSON text messages (input, settings, acks);
// the server answers with JSON text messages (what the page shows) and binary frames (a fixed header and a
// JPEG or PNG). Every client message is parsed and validated here, before anything acts on it: a message
// that is not exactly one of the shapes below is refused whole (docs/design.md, "Serving": input from the
// network is validated and bounded like file input). The downloads (/export.las, and the profile's
// /profile.png, /profile.las, /profile.csv) are HTTP requests of their own, whose queries export.h validates.
//
// Positions are normalized to the canvas (0..1 from the left and top edge): the server scales them to its
// viewport, so they do not depend on the page's device pixel ratio or on --max-size clamping the image.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <glm/glm.hpp>

#include "cloud/annotations.h"
#include "render/method_table.h"
#include "view/session.h"

namespace pointrast::view::web {

// The longest valid message is about 400 bytes; anything over this is refused unread.
constexpr size_t kMaxMessageBytes = 1024;
// A resize may ask for at most this many pixels per side; --max-size then bounds what is rendered.
constexpr uint32_t kMaxCanvasSide = 16384;
// Normalized positions may lie this far outside the canvas (a drag continues past its edge).
constexpr double kPositionMargin = 4.0;
// Wheel steps in one message (a browser's fastest wheel sends a few per event).
constexpr double kMaxWheelSteps = 50.0;

enum class MessageType {
  Resize,      // w, h: the canvas size in device pixels (the first message of a client)
  Down,        // b (0 left, 1 middle, 2 right, as the DOM numbers them), x, y
  Move,        // x, y
  Up,          // b, x, y
  DoubleClick, // x, y
  Wheel,       // x, y, steps (positive: zoom in)
  Key,         // key (a Key's name), down, shift
  Settings,    // any of the SettingsChange fields below, at least one
  Options,     // supersample (1, 2, 4) and/or keyframeSeconds
  Stream,      // motionScale (0.25..1), quality and/or motionQuality (10..100)
  Action,      // name: clearKeyframes, downloadPath
  Ack,         // frame: the id of a frame the page has drawn
  PickPoint,   // x, y, and measure ("distance", "height", "area"): the pick tool, adding a vertex if measuring
  Measure,     // op: finish, delete (index), clear, download, move (x, y, tx, ty): the measurements
};

// Move: the vertex drawn nearest (x, y) moves to the point picked at (tx, ty) (scene_view.h moveVertexTool).
enum class MeasureOp { Finish, Delete, Clear, Download, Move };

enum class ClientAction { ClearKeyframes, DownloadPath };

// A "settings" message: the view settings it changes, each held to render's range for its option.
//   method          a method this device runs, by name
//   background      [r, g, b], 0..255
//   depth           "float" or "int40"
//   color           "auto" or a color source (colorSourceName)
//   colorRange      [lo, hi], finite, lo < hi, or null for the percentiles
//   pointSize       1..kMaxPointSize;  pointSizeMax likewise;  pointShape "square"/"disc"
//   pointSizeMode   "fixed" or "attenuated"
//   dilate          0..kMaxDilateRadius (integer)
//   edlStrength     0..kMaxEdlStrength (0: off);  edlRadius (0, 16]
//   minNodePx       0..kMaxMinNodePx;  pointBudget 0..kMaxPointBudget;  gpuMemory 0..kMaxGpuMemory (bytes)
//   stereo, crossed true/false;  ipd 0..1e12 (scene units, 0: auto)
//   foveated        true/false;  foveaRadius 0..1;  foveaPeriphery 1..kMaxFoveaPeriphery
//   clipBox         [x0, y0, z0, x1, y1, z1], finite, min <= max, or null;  clipMode "inside"/"outside"
struct SettingsChange {
  std::optional<Method> method;
  std::optional<uint32_t> background; // RGBA8, alpha 255
  std::optional<DepthMode> depth;
  bool color = false; // colorSource is given (nullopt: auto)
  std::optional<DisplayColorMode::Source> colorSource;
  bool range = false; // colorRange is given (nullopt: the percentiles)
  std::optional<ColorRange> colorRange;
  std::optional<float> pointSize, pointSizeMax, edlStrength, edlRadius;
  std::optional<PointShape> pointShape;
  std::optional<PointSizeMode> pointSizeMode;
  std::optional<uint32_t> dilate;
  std::optional<double> minNodePx;
  std::optional<uint64_t> pointBudget, gpuMemory;
  std::optional<bool> stereo, crossed, foveated;
  std::optional<double> ipd, foveaRadius, foveaPeriphery;
  bool clip = false;                 // clipBox given: the view's axis-aligned clip boxes become this one
  std::optional<ClipBox> clipBox;    // null: none
  std::optional<ClipMode> clipMode;  // inside or outside
};

// The settings with the change applied; a new color source without a range drops the old range. Throws
// InputError (validateSettings) when the result is not a valid whole, e.g. a range for the RGB colors.
ViewSettings applySettings(const ViewSettings& settings, const SettingsChange& change);

struct ClientMessage {
  MessageType type = MessageType::Move;
  std::optional<uint32_t> seq; // the client's input sequence number, echoed in the frames it causes
  glm::dvec2 position{0};      // normalized
  MouseButton button = MouseButton::Left;
  double steps = 0;
  Key key = Key::Forward;
  bool down = false, shift = false;
  uint32_t width = 0, height = 0;
  SettingsChange settings;
  std::optional<uint32_t> supersample;
  std::optional<double> keyframeSeconds;
  std::optional<double> motionScale;
  std::optional<int> quality, motionQuality;
  ClientAction action = ClientAction::ClearKeyframes;
  uint32_t frame = 0;
  std::optional<AnnotationKind> measure; // PickPoint: the kind of measurement the point extends
  MeasureOp measureOp = MeasureOp::Finish;
  glm::dvec2 target{0}; // Measure Move: where the vertex goes (position: where it was grabbed)
  uint32_t index = 0;
  double received = 0; // seconds on the steady clock: when the server read it (not from the wire)
};

// One text message parsed and validated against the methods this device runs. Returns the message, or
// one sentence saying why it was refused.
std::variant<ClientMessage, std::string> parseClientMessage(std::string_view text,
                                                            std::span<const Method> methods);

// Key names on the wire (the Key enumerators' names); Quit is not among them: no client stops the server.
std::optional<Key> keyFromName(std::string_view name);
const char* keyName(Key key);

// Binary messages from the server start with this header (little-endian), followed by the payload.
constexpr uint32_t kFrameMagic = 0x31465250u;      // "PRF1": a frame, JPEG payload
constexpr uint32_t kScreenshotMagic = 0x31535250u; // "PRS1": a screenshot, PNG payload
constexpr size_t kFrameHeaderBytes = 32;

struct FrameHeader {
  uint32_t magic = kFrameMagic;
  uint32_t frame = 0;                     // id, acknowledged by the client once drawn
  uint32_t seq = 0;                       // the last input sequence number applied before it was rendered
  uint16_t width = 0, height = 0;         // of the image
  uint16_t viewWidth = 0, viewHeight = 0; // of the viewport it shows (larger for a motion frame)
  uint8_t quality = 0;                    // JPEG quality
  uint8_t flags = 0;                      // kFrameFull: the full frame at rest
  float renderMs = 0, encodeMs = 0;
};
constexpr uint8_t kFrameFull = 1;

void writeFrameHeader(const FrameHeader& header, uint8_t* out);
FrameHeader readFrameHeader(const uint8_t* in);

} // namespace pointrast::view::web
