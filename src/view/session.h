// The interactive session every front end shares (the desktop window, the browser viewer): it turns input
// events into camera moves and requests, holds the view settings, decides when a new frame must be
// rendered, records keyframes and keeps the statistics of recent frames. No GPU and no window here: a
// front end translates its events into these calls, asks needsFrame(), renders with SceneView and reports
// the frame back.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>

#include <glm/glm.hpp>

#include "cloud/cloud.h"
#include "cloud/point_filter.h"
#include "render/lod/foveation.h"
#include "render/lod/lod_stats.h"
#include "render/post/post_settings.h"
#include "render/renderer.h"
#include "render/stereo.h"
#include "view/camera_path.h"
#include "view/measure_tool.h"
#include "view/navigation.h"

namespace pointrast::view {

// What a frame is rendered with: every option of `render` a viewer offers. Every change goes through
// Session::setSettings, which compares, so an unchanged panel costs no frame.
struct ViewSettings {
  Method method;                     // the first row of the method table: atomicmin
  uint32_t background = 0xFF000000u; // RGBA8
  DepthMode depth = DepthMode::Float;
  PostSettings post; // point size, shape and attenuation, dilation, eye-dome lighting
  // Coloring (render --color, --color-range): no source is the automatic choice (displayColorMode); a
  // range applies to intensity and elevation only (lo < hi).
  std::optional<DisplayColorMode::Source> colorSource;
  std::optional<ColorRange> colorRange;
  // Level of detail (octree methods): render --min-node-px, --point-budget (0: no limit) and --gpu-memory
  // (bytes of the node cache; 0: the default, half the device's).
  double minNodePx = 100;
  uint64_t pointBudget = 0;
  uint64_t gpuMemory = 0;
  // Clip volumes drawn per frame (RenderSettings::filter): --clip-box, --clip-polygon, --clip-mode inside or
  // outside.
  PointFilter filter;
  // Stereo (render --stereo, --ipd, --convergence; batch and LOD methods): both eyes side by side, each
  // half the viewport wide, the left eye on the left unless eyes.crossed.
  bool stereo = false;
  StereoSettings eyes;
  // Foveated level of detail (render --foveated, --fovea-radius, --fovea-periphery; LOD methods).
  lod::Foveation foveation;
  bool operator==(const ViewSettings& other) const;
};

// The limits the panels and the browser's messages hold every setting to (those of render's options).
constexpr double kMaxMinNodePx = 10000;
constexpr uint64_t kMaxPointBudget = 1ull << 40;
constexpr uint64_t kMaxGpuMemory = 1ull << 44; // 16 TiB: any device's memory
constexpr float kMaxEdlStrength = 10.0f;       // the panels' bound; render takes any finite strength
constexpr double kMaxFoveaPeriphery = 100.0;   // the panels' bound; render takes any finite factor

// What of the settings the method takes: the resolve stage (point size, dilation, eye-dome lighting) is
// dropped for methods that keep no depth per pixel (MethodOutput::ColorOnly) and int40 depth for methods
// without it, so that switching the method never makes a frame impossible. Panels show what is dropped
// as disabled.
ViewSettings applicable(const ViewSettings& settings);
bool takesPost(Method method);
bool takesInt40(Method method);
bool takesStereo(Method method);    // the batch and LOD methods draw both eyes in one pass
bool takesFoveation(Method method); // the LOD methods
// The size of one eye's image for a viewport: half its width (at least 1) in stereo, all of it otherwise.
Viewport eyeViewport(const ViewSettings& settings, Viewport viewport);

// The applicable settings as `pointrast render` options, only those that differ from render's defaults, e.g.
// "--method batch --color intensity --point-size 3 --edl": with the camera's options (describeCamera)
// they reproduce the viewer's image with render.
std::string describeSettings(const ViewSettings& settings);
// The camera's options (describeCamera) and then the settings': what the C key prints.
std::string describeView(const Camera& camera, const ViewSettings& settings);
// Throws InputError, naming the setting, for a value render would refuse (the ranges above,
// validatePostSettings, a color range that is not lo < hi or given for a source without a ramp).
void validateSettings(const ViewSettings& settings);

// Front-end state that is not part of the rendered image.
struct ViewOptions {
  bool panel = true;        // the settings panel is shown
  uint32_t supersample = 1; // screenshots: rendered at this multiple, box-filtered down
  double keyframeSeconds = kDefaultKeyframeSeconds; // spacing of keyframes recorded with K
};

// Keys the session understands; front ends map their key codes to these.
enum class Key {
  Forward,
  Back,
  Left,
  Right,
  Down,
  Up,          // fly: W S A D Q E
  FrameAll,    // F
  Keyframe,    // K
  TogglePanel, // H
  PrintCamera, // C
  Screenshot,  // F12
  ViewTop,
  ViewBottom,
  ViewFront,
  ViewBack,
  ViewLeft,
  ViewRight,
  ViewIso, // 8 2 5 0 4 6 and 1
  Quit,    // Escape
};

enum class MouseButton { Left, Right, Middle };

// Statistics of one rendered frame, reported by the front end.
struct FrameReport {
  double renderMs = 0;  // GPU time of the point rendering (clear + draw + resolve)
  double presentMs = 0; // GPU time of showing the image (and drawing the panel), where the front end has it
  uint64_t points = 0;  // points submitted
  std::optional<BatchStats> batch;
  std::optional<PostStats> post;    // GPU time of the resolve stage's passes, when it ran
  std::optional<lod::LodStats> lod; // octree methods: selection, drawing, streaming, the node cache
  std::string status;               // a line for the panel, e.g. "building octree 42 %" or a streaming error
  uint64_t gpuBytes = 0;            // GPU memory the scene and targets occupy
  double seconds = 0;               // wall-clock time of the frame on the host (render to present)
};

// Medians over the last kStatsWindow frames.
struct Statistics {
  uint64_t frames = 0; // frames rendered since the start
  double renderMs = 0, presentMs = 0, hostMs = 0;
  uint64_t points = 0;
  std::optional<BatchStats> batch;  // of the last frame
  std::optional<PostStats> post;    // medians of each pass, over the recent frames that ran the stage
  std::optional<lod::LodStats> lod; // of the last frame
  std::string status;               // of the last frame
  // Octree methods: bytes of the source's files streamed per second, over the recent frames' wall time.
  double streamedBytesPerSecond = 0;
  uint64_t gpuBytes = 0;
};
constexpr size_t kStatsWindow = 60;

// What a front end must do on the session's behalf, taken (and cleared) by the front end.
struct Requests {
  std::optional<glm::dvec2> pick; // read the depth under this viewport position, then call pivotPicked
  std::optional<glm::dvec2> toolPick; // the pick tool at this position (scene_view.h pickTool)
  bool toolMeasure = false;           // ... adding the point to a measurement
  // Ctrl+drag from a measurement's vertex: move it to the point under the second position
  // (scene_view.h moveVertexTool).
  std::optional<std::pair<glm::dvec2, glm::dvec2>> vertexMove;
  bool screenshot = false;
  bool printCamera = false;
  bool quit = false;
};

// Something besides input that changes what a frame shows: the level-of-detail engine, when nodes
// arrived since the last frame. The session asks it on every needsFrame().
class ContentSource {
public:
  virtual ~ContentSource() = default;
  virtual bool changedSinceLastFrame() = 0;
};

class Session {
public:
  Session(const Bounds& bounds, const Camera& camera, Viewport viewport, const ViewSettings& settings = {});

  // Input, in viewport pixels (x right, y down).
  void mouseDown(MouseButton button, glm::dvec2 position);
  void mouseMove(glm::dvec2 position);
  void mouseUp(MouseButton button, glm::dvec2 position);
  void doubleClick(glm::dvec2 position); // asks for a pick; pivotPicked sets the pivot
  void toolClick(glm::dvec2 position, bool measure); // Ctrl+click: asks for the pick tool (Requests::toolPick)
  // Ctrl+drag: asks to move the measurement's vertex under `from` (Requests::vertexMove).
  void toolDrag(glm::dvec2 from, glm::dvec2 to);
  // Wheel steps (positive: zoom in); `depth` is the linear depth under the cursor when the front end has
  // it (see Navigation::zoom).
  void wheel(glm::dvec2 position, double steps, std::optional<double> depth = std::nullopt);
  void keyDown(Key key, bool shift = false);
  void keyUp(Key key);
  void resize(Viewport viewport);
  // Advances time-based motion (fly keys held); returns whether the camera moved.
  bool advance(double seconds);

  // Answer to Requests::pick: the point under the position, or nothing (an empty pixel).
  void pivotPicked(std::optional<glm::dvec3> point);
  Requests takeRequests();

  const Camera& camera() const { return navigation_.camera(); }
  const glm::dvec3& pivot() const { return navigation_.pivot(); }
  Viewport viewport() const { return viewport_; }
  Navigation& navigation() { return navigation_; }
  const Navigation& navigation() const { return navigation_; }
  void setCamera(const Camera& camera);

  const ViewSettings& settings() const { return settings_; }
  void setSettings(const ViewSettings& settings);
  ViewOptions& options() { return options_; }
  const ViewOptions& options() const { return options_; }

  CameraPath& path() { return path_; }
  const CameraPath& path() const { return path_; }
  // The measurements drawn with the pick tool and those loaded from --annotations.
  MeasureTool& measurements() { return measurements_; }
  const MeasureTool& measurements() const { return measurements_; }
  void recordKeyframe() { path_.append(camera(), options_.keyframeSeconds); }

  // Whether the image is stale (camera, viewport, settings or content changed since the last frame), or
  // motion is under way that will change it.
  bool needsFrame();
  // Whether keys are held that move the camera over time: the front end keeps the loop running.
  bool animating() const { return fly_.any(); }
  void setContentSource(ContentSource* source) { content_ = source; }
  // Marks the image stale without a camera or settings change (e.g. a method's device state was reset).
  void invalidate() { ++generation_; }
  void frameRendered(const FrameReport& report);
  const Statistics& statistics() const { return statistics_; }

private:
  void flyKey(Key key, int value);
  Navigation navigation_;
  Viewport viewport_;
  ViewSettings settings_;
  ViewOptions options_;
  CameraPath path_;
  MeasureTool measurements_;
  Requests requests_;
  FlyInput fly_;
  int flyKeys_[6] = {0, 0, 0, 0, 0, 0}; // held state of Forward..Up
  uint64_t generation_ = 1, renderedGeneration_ = 0;
  ContentSource* content_ = nullptr;
  glm::dvec2 cursor_{0};
  std::deque<FrameReport> recent_;
  // (when, LodStats::bytesStreamed) of the frames of the last two seconds
  std::deque<std::pair<std::chrono::steady_clock::time_point, uint64_t>> streamed_;
  Statistics statistics_;
};

// "top", "front", ...: the standard view a key selects, if any.
std::optional<StandardView> standardViewForKey(Key key);

} // namespace pointrast::view
