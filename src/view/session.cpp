#include "view/session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "base/error.h"
#include "cloud/attribute_colors.h"
#include "gpu/timer.h"

namespace pointrast::view {

std::optional<StandardView> standardViewForKey(Key key) {
  switch (key) {
  case Key::ViewTop:
    return StandardView::Top;
  case Key::ViewBottom:
    return StandardView::Bottom;
  case Key::ViewFront:
    return StandardView::Front;
  case Key::ViewBack:
    return StandardView::Back;
  case Key::ViewLeft:
    return StandardView::Left;
  case Key::ViewRight:
    return StandardView::Right;
  case Key::ViewIso:
    return StandardView::Iso;
  default:
    return std::nullopt;
  }
}

bool ViewSettings::operator==(const ViewSettings& o) const {
  auto samePost = [](const PostSettings& a, const PostSettings& b) {
    return a.pointSize == b.pointSize && a.shape == b.shape && a.sizeMode == b.sizeMode &&
           a.maxPointSize == b.maxPointSize && a.dilate == b.dilate && a.edlStrength == b.edlStrength &&
           a.edlRadius == b.edlRadius;
  };
  auto sameRange = [](const std::optional<ColorRange>& a, const std::optional<ColorRange>& b) {
    return a.has_value() == b.has_value() && (!a || (a->lo == b->lo && a->hi == b->hi));
  };
  return method == o.method && background == o.background && depth == o.depth && samePost(post, o.post) &&
         colorSource == o.colorSource && sameRange(colorRange, o.colorRange) && minNodePx == o.minNodePx &&
         pointBudget == o.pointBudget && gpuMemory == o.gpuMemory && filter == o.filter &&
         stereo == o.stereo && eyes.separation == o.eyes.separation &&
         eyes.convergence == o.eyes.convergence && eyes.crossed == o.eyes.crossed &&
         foveation.enabled == o.foveation.enabled && foveation.radius == o.foveation.radius &&
         foveation.periphery == o.foveation.periphery;
}

namespace {

// Shortest text that reads back as the same float or double.
std::string number(double v) {
  char text[32];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  return text;
}

std::string number(float v) {
  char text[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, double(v));
    if (std::strtof(text, nullptr) == v) break;
  }
  return text;
}

bool hasRamp(DisplayColorMode::Source source) {
  return source == DisplayColorMode::Source::Intensity || source == DisplayColorMode::Source::Elevation;
}

} // namespace

bool takesPost(Method method) {
  return methodInfo(method).output != MethodOutput::ColorOnly;
}

bool takesInt40(Method method) {
  return methodInfo(method).int40Shader != nullptr;
}

bool takesStereo(Method method) {
  const SceneLayout layout = methodInfo(method).layout;
  return layout == SceneLayout::Batched || layout == SceneLayout::Octree;
}

bool takesFoveation(Method method) {
  return methodInfo(method).layout == SceneLayout::Octree;
}

Viewport eyeViewport(const ViewSettings& settings, Viewport viewport) {
  if (!settings.stereo || !takesStereo(settings.method)) return viewport;
  return {std::max(1u, viewport.width / 2), viewport.height};
}

ViewSettings applicable(const ViewSettings& settings) {
  ViewSettings s = settings;
  if (!takesPost(s.method)) s.post = PostSettings{};
  if (!takesInt40(s.method)) s.depth = DepthMode::Float;
  if (!takesStereo(s.method)) s.stereo = false;
  if (!s.stereo) s.eyes = StereoSettings{};
  if (!takesFoveation(s.method)) s.foveation.enabled = false;
  if (!s.foveation.enabled) s.foveation = lod::Foveation{};
  return s;
}

std::string describeSettings(const ViewSettings& settings) {
  const ViewSettings s = applicable(settings);
  const ViewSettings defaults;
  const PostSettings& p = s.post;
  const PostSettings& d = defaults.post;
  std::string out;
  auto add = [&](const std::string& option, const std::string& value = {}) {
    if (!out.empty()) out += ' ';
    out += option;
    if (!value.empty()) out += ' ' + value;
  };
  if (s.method != defaults.method) add("--method", methodName(s.method));
  if (s.depth != defaults.depth) add("--depth", depthModeName(s.depth));
  if (s.background != defaults.background)
    add("--background", std::to_string(s.background & 0xFF) + "," +
                            std::to_string((s.background >> 8) & 0xFF) + "," +
                            std::to_string((s.background >> 16) & 0xFF));
  if (s.colorSource) add("--color", colorSourceName(*s.colorSource));
  if (s.colorSource && s.colorRange && hasRamp(*s.colorSource))
    add("--color-range", number(s.colorRange->lo) + "," + number(s.colorRange->hi));
  if (p.pointSize != d.pointSize) add("--point-size", number(p.pointSize));
  if (p.shape != d.shape) add("--point-shape", pointShapeName(p.shape));
  if (p.sizeMode != d.sizeMode) add("--point-size-mode", pointSizeModeName(p.sizeMode));
  if (p.maxPointSize != d.maxPointSize) add("--point-size-max", number(p.maxPointSize));
  if (p.dilate != d.dilate) add("--dilate", std::to_string(p.dilate));
  if (p.edlStrength > 0) {
    add("--edl");
    if (p.edlStrength != 1.0f) add("--edl-strength", number(p.edlStrength));
    if (p.edlRadius != d.edlRadius) add("--edl-radius", number(p.edlRadius));
  }
  if (s.minNodePx != defaults.minNodePx) add("--min-node-px", number(s.minNodePx));
  if (s.pointBudget != defaults.pointBudget) add("--point-budget", std::to_string(s.pointBudget));
  if (s.gpuMemory != defaults.gpuMemory) add("--gpu-memory", std::to_string(s.gpuMemory));
  if (s.stereo) {
    add("--stereo");
    if (s.eyes.separation > 0) add("--ipd", number(s.eyes.separation));
    if (std::isinf(s.eyes.convergence))
      add("--convergence", "inf");
    else if (s.eyes.convergence > 0)
      add("--convergence", number(s.eyes.convergence));
    if (s.eyes.crossed) add("--stereo-layout", "cross-eyed");
  }
  if (s.foveation.enabled) {
    const lod::Foveation f;
    add("--foveated");
    if (s.foveation.radius != f.radius) add("--fovea-radius", number(s.foveation.radius));
    if (s.foveation.periphery != f.periphery) add("--fovea-periphery", number(s.foveation.periphery));
  }
  return out;
}

std::string describeView(const Camera& camera, const ViewSettings& settings) {
  std::string options = describeSettings(settings);
  return describeCamera(camera) + (options.empty() ? "" : " " + options);
}

void validateSettings(const ViewSettings& s) {
  validatePostSettings(s.post);
  if (s.post.edlStrength > kMaxEdlStrength)
    throw InputError("eye-dome lighting strength must be at most " + number(kMaxEdlStrength));
  if (s.colorRange) {
    if (!s.colorSource || !hasRamp(*s.colorSource))
      throw InputError("a color range applies to the intensity and elevation colors");
    if (!(std::isfinite(s.colorRange->lo) && std::isfinite(s.colorRange->hi) &&
          s.colorRange->lo < s.colorRange->hi))
      throw InputError("a color range must be finite numbers lo < hi");
  }
  if (!(s.minNodePx >= 0 && s.minNodePx <= kMaxMinNodePx))
    throw InputError("the minimum node size must be 0.." + number(kMaxMinNodePx) + " pixels");
  if (s.pointBudget > kMaxPointBudget) throw InputError("the point budget is out of range");
  if (s.gpuMemory > kMaxGpuMemory) throw InputError("the GPU memory budget is out of range");
  validateStereo(s.eyes);
  if (!(s.foveation.radius >= 0 && s.foveation.radius <= 1))
    throw InputError("the fovea's radius must be between 0 and 1");
  if (!(s.foveation.periphery >= 1 && s.foveation.periphery <= kMaxFoveaPeriphery))
    throw InputError("the periphery factor must be 1.." + number(kMaxFoveaPeriphery));
}

Session::Session(const Bounds& bounds, const Camera& camera, Viewport viewport, const ViewSettings& settings)
    : navigation_(bounds, camera), viewport_(viewport), settings_(settings) {}

void Session::mouseDown(MouseButton button, glm::dvec2 position) {
  cursor_ = position;
  navigation_.beginDrag(button == MouseButton::Left ? DragMode::Orbit : DragMode::Pan, position);
}

void Session::mouseMove(glm::dvec2 position) {
  cursor_ = position;
  if (navigation_.dragMode() != DragMode::None && navigation_.drag(position, viewport_)) ++generation_;
}

void Session::mouseUp(MouseButton, glm::dvec2 position) {
  mouseMove(position);
  navigation_.endDrag();
}

void Session::doubleClick(glm::dvec2 position) {
  navigation_.endDrag();
  requests_.pick = position;
}

void Session::toolClick(glm::dvec2 position, bool measure) {
  navigation_.endDrag();
  requests_.toolPick = position;
  requests_.toolMeasure = measure;
}

void Session::toolDrag(glm::dvec2 from, glm::dvec2 to) {
  navigation_.endDrag();
  requests_.vertexMove = {from, to};
}

void Session::wheel(glm::dvec2 position, double steps, std::optional<double> depth) {
  if (steps == 0) return;
  navigation_.zoom(position, steps, viewport_, depth);
  ++generation_;
}

void Session::flyKey(Key key, int value) {
  flyKeys_[int(key) - int(Key::Forward)] = value;
  fly_.forward = flyKeys_[0] - flyKeys_[1];
  fly_.right = flyKeys_[3] - flyKeys_[2];
  fly_.up = flyKeys_[5] - flyKeys_[4];
}

void Session::keyDown(Key key, bool shift) {
  if (key >= Key::Forward && key <= Key::Up) {
    fly_.fast = shift;
    flyKey(key, 1);
    return;
  }
  if (auto view = standardViewForKey(key)) {
    navigation_.viewFrom(*view, viewport_);
    ++generation_;
    return;
  }
  switch (key) {
  case Key::FrameAll:
    navigation_.frameAll(viewport_);
    ++generation_;
    break;
  case Key::Keyframe:
    recordKeyframe();
    break;
  case Key::TogglePanel:
    options_.panel = !options_.panel;
    break;
  case Key::PrintCamera:
    requests_.printCamera = true;
    break;
  case Key::Screenshot:
    requests_.screenshot = true;
    break;
  case Key::Quit:
    requests_.quit = true;
    break;
  default:
    break;
  }
}

void Session::keyUp(Key key) {
  if (key >= Key::Forward && key <= Key::Up) flyKey(key, 0);
}

void Session::resize(Viewport viewport) {
  if (viewport == viewport_ || viewport.width == 0 || viewport.height == 0) return;
  viewport_ = viewport;
  ++generation_;
}

bool Session::advance(double seconds) {
  // A long stall (a slow frame, a dragged window) must not throw the camera far away.
  if (!navigation_.fly(fly_, std::min(seconds, 0.1))) return false;
  ++generation_;
  return true;
}

void Session::pivotPicked(std::optional<glm::dvec3> point) {
  if (point) navigation_.setPivot(*point);
}

Requests Session::takeRequests() {
  return std::exchange(requests_, Requests{});
}

void Session::setCamera(const Camera& camera) {
  navigation_.setCamera(camera);
  ++generation_;
}

void Session::setSettings(const ViewSettings& settings) {
  if (settings == settings_) return;
  settings_ = settings;
  ++generation_;
}

bool Session::needsFrame() {
  if (content_ && content_->changedSinceLastFrame()) ++generation_;
  return generation_ != renderedGeneration_ || fly_.any();
}

void Session::frameRendered(const FrameReport& report) {
  renderedGeneration_ = generation_;
  recent_.push_back(report);
  if (recent_.size() > kStatsWindow) recent_.pop_front();
  auto medianOf = [&](auto get) {
    std::vector<double> values;
    for (const FrameReport& r : recent_)
      if (auto v = get(r)) values.push_back(*v);
    return values.empty() ? 0.0 : gpu::median(values);
  };
  statistics_.frames++;
  statistics_.renderMs = medianOf([](const FrameReport& r) { return std::optional(r.renderMs); });
  statistics_.presentMs = medianOf([](const FrameReport& r) { return std::optional(r.presentMs); });
  statistics_.hostMs = medianOf([](const FrameReport& r) { return std::optional(r.seconds); }) * 1e3;
  statistics_.points = report.points;
  statistics_.batch = report.batch;
  statistics_.post.reset();
  if (report.post) {
    auto pass = [&](double PostStats::*member) {
      return medianOf(
          [&](const FrameReport& r) { return r.post ? std::optional((*r.post).*member) : std::nullopt; });
    };
    statistics_.post =
        PostStats{pass(&PostStats::splatMs), pass(&PostStats::dilateMs), pass(&PostStats::composeMs)};
  }
  statistics_.lod = report.lod;
  statistics_.status = report.status;
  statistics_.gpuBytes = report.gpuBytes;
  // Streaming rate: the bytes the source's files gave over the wall time of the recent frames that streamed.
  const auto now = std::chrono::steady_clock::now();
  streamed_.push_back({now, report.lod ? report.lod->bytesStreamed : 0});
  while (streamed_.size() > 1 && now - streamed_.front().first > std::chrono::seconds(2))
    streamed_.pop_front();
  statistics_.streamedBytesPerSecond = 0;
  if (report.lod && streamed_.size() > 1) {
    double seconds = std::chrono::duration<double>(now - streamed_.front().first).count();
    uint64_t first = streamed_.front().second, last = streamed_.back().second;
    if (seconds > 0 && last > first) statistics_.streamedBytesPerSecond = double(last - first) / seconds;
  }
}

} // namespace pointrast::view
