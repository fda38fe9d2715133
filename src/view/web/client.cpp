#include "view/web/client.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>

#include "base/error.h"
#include "cloud/attribute_colors.h"
#include "io/annotations_file.h"
#include "io/writer.h"

namespace pointrast::view::web {

namespace {

using Json = nlohmann::json;

// While fly keys are held the camera moves every frame: the render thread comes back this often.
constexpr double kFlyStepSeconds = 1.0 / 60.0;

Json vec(const glm::dvec3& v) {
  return {v.x, v.y, v.z};
}

Json rgb(uint32_t rgba) {
  return {rgba & 0xFF, (rgba >> 8) & 0xFF, (rgba >> 16) & 0xFF};
}

// The settings as the page's controls show them (the names of the "settings" message), and as render
// options.
Json settingsJson(const ViewSettings& s) {
  const PostSettings& p = s.post;
  Json j = {{"method", methodName(s.method)},
            {"background", rgb(s.background)},
            {"depth", depthModeName(s.depth)},
            {"color", s.colorSource ? colorSourceName(*s.colorSource) : "auto"},
            {"colorRange", s.colorRange ? Json{s.colorRange->lo, s.colorRange->hi} : Json()},
            {"pointSize", p.pointSize},
            {"pointSizeMax", p.maxPointSize},
            {"pointShape", pointShapeName(p.shape)},
            {"pointSizeMode", pointSizeModeName(p.sizeMode)},
            {"dilate", p.dilate},
            {"edlStrength", p.edlStrength},
            {"edlRadius", p.edlRadius},
            {"minNodePx", s.minNodePx},
            {"pointBudget", s.pointBudget},
            {"gpuMemory", s.gpuMemory},
            {"stereo", s.stereo},
            {"crossed", s.eyes.crossed},
            {"ipd", s.eyes.separation},
            {"foveated", s.foveation.enabled},
            {"foveaRadius", s.foveation.radius},
            {"foveaPeriphery", s.foveation.periphery},
            {"clipBox", s.filter.boxes.empty() ? Json(nullptr)
                                               : Json{s.filter.boxes[0].min.x, s.filter.boxes[0].min.y,
                                                      s.filter.boxes[0].min.z, s.filter.boxes[0].max.x,
                                                      s.filter.boxes[0].max.y, s.filter.boxes[0].max.z}},
            {"clipMode", s.filter.clipMode == ClipMode::Outside ? "outside" : "inside"},
            {"takesStereo", takesStereo(s.method)},
            {"takesFoveation", takesFoveation(s.method)},
            {"takesPost", takesPost(s.method)},
            {"takesInt40", takesInt40(s.method)},
            {"octree", methodInfo(s.method).layout == SceneLayout::Octree},
            {"options", describeSettings(s)}};
  return j;
}

} // namespace

Viewport clampViewport(uint32_t width, uint32_t height, Viewport maxSize) {
  double scale = std::min({1.0, double(maxSize.width) / width, double(maxSize.height) / height});
  if (scale >= 1.0) return {width, height};
  return {std::max(1u, uint32_t(std::lround(width * scale))),
          std::max(1u, uint32_t(std::lround(height * scale)))};
}

Viewport scaleViewport(Viewport viewport, double scale) {
  return {std::max(1u, uint32_t(std::lround(viewport.width * scale))),
          std::max(1u, uint32_t(std::lround(viewport.height * scale)))};
}

WebClient::WebClient(const ClientSetup& setup, FrameStream& stream)
    : setup_(setup), stream_(stream), full_(*setup.context, *setup.cloud),
      motion_(*setup.context, *setup.cloud), settings_(setup.stream) {}

glm::dvec2 WebClient::pixels(glm::dvec2 normalized) const {
  Viewport v = session_->viewport();
  return {normalized.x * v.width, normalized.y * v.height};
}

void WebClient::resize(uint32_t width, uint32_t height) {
  Viewport viewport = clampViewport(width, height, setup_.maxSize);
  if (!session_) {
    Camera camera = setup_.camera ? *setup_.camera
                                  : overviewCamera(setup_.cloud->bounds(), viewport.aspect(), setup_.fovY,
                                                   setup_.framing);
    session_.emplace(setup_.cloud->bounds(), camera, viewport, setup_.settings);
    session_->setContentSource(&full_);
    session_->measurements().load(setup_.annotations);
    sendMeasurements();
    return;
  }
  session_->resize(viewport);
}

void WebClient::pointer(const ClientMessage& m) {
  glm::dvec2 at = pixels(m.position);
  switch (m.type) {
  case MessageType::Down:
    session_->mouseDown(m.button, at);
    break;
  case MessageType::Move:
    session_->mouseMove(at);
    break;
  case MessageType::Up:
    session_->mouseUp(m.button, at);
    break;
  case MessageType::DoubleClick:
    session_->doubleClick(at);
    break;
  case MessageType::Wheel:
    // Gathered: one depth read for all the steps that arrived since the last frame, as on the desktop.
    wheel_ += m.steps;
    wheelAt_ = at;
    break;
  default:
    break;
  }
}

void WebClient::receive(const ClientMessage& m) {
  if (m.seq) seq_ = *m.seq;
  if (m.type == MessageType::Resize) {
    resize(m.width, m.height);
    return;
  }
  if (m.type == MessageType::Stream) {
    if (m.motionScale) settings_.motionScale = *m.motionScale;
    if (m.quality) settings_.quality = *m.quality;
    if (m.motionQuality) settings_.motionQuality = *m.motionQuality;
    stateChanged_ = true;
    return;
  }
  if (!session_) return; // input before the canvas size means nothing yet
  if (!inputSince_ && m.seq) inputSince_ = m.received;
  switch (m.type) {
  case MessageType::Down:
  case MessageType::Move:
  case MessageType::Up:
  case MessageType::DoubleClick:
  case MessageType::Wheel: {
    Camera before = session_->camera();
    pointer(m);
    // The wheel's steps are applied at the next frame; a drag's moves now.
    if (m.type == MessageType::Wheel || !sameCamera(before, session_->camera())) quality_.input(m.received);
    break;
  }
  case MessageType::Key:
    if (m.down)
      session_->keyDown(m.key, m.shift);
    else
      session_->keyUp(m.key);
    stateChanged_ = true; // keyframes, the panel's visibility
    break;
  case MessageType::Settings:
    // A change that makes no valid whole (a range for a source without a ramp) is answered, not applied.
    try {
      session_->setSettings(applySettings(session_->settings(), m.settings));
    } catch (const InputError& e) {
      stream_.submitText(Json{{"t", "refused"}, {"text", e.what()}}.dump());
    }
    stateChanged_ = true;
    break;
  case MessageType::Options:
    if (m.supersample) session_->options().supersample = *m.supersample;
    if (m.keyframeSeconds) session_->options().keyframeSeconds = *m.keyframeSeconds;
    stateChanged_ = true;
    break;
  case MessageType::Action:
    if (m.action == ClientAction::ClearKeyframes) session_->path().clear();
    if (m.action == ClientAction::DownloadPath)
      stream_.submitText(Json{{"t", "path"}, {"path", Json::parse(session_->path().toJson())}}.dump());
    stateChanged_ = true;
    break;
  case MessageType::PickPoint:
    toolPick_ = {pixels(m.position), m.measure};
    break;
  case MessageType::Measure: {
    MeasureTool& tool = session_->measurements();
    if (m.measureOp == MeasureOp::Move) {
      vertexMove_ = {pixels(m.position), pixels(m.target)}; // needs a pick: served with the requests
      break;
    }
    if (m.measureOp == MeasureOp::Finish) tool.finish();
    if (m.measureOp == MeasureOp::Delete && !tool.remove(m.index))
      stream_.submitText(
          Json{{"t", "refused"}, {"text", "no measurement " + std::to_string(m.index)}}.dump());
    if (m.measureOp == MeasureOp::Clear) tool.clear();
    if (m.measureOp == MeasureOp::Download)
      stream_.submitText(Json{{"t", "annotations"}, {"text", io::annotationsJson(tool.complete())}}.dump());
    else
      sendMeasurements();
    session_->invalidate(); // the overlay changed
    break;
  }
  default:
    break;
  }
}

void WebClient::sendMeasurements() {
  stream_.submitText(
      Json{{"t", "measurements"}, {"list", Json::parse(session_->measurements().json())}}.dump());
}

void WebClient::serveRequests() {
  if (toolPick_) {
    const auto [at, kind] = *std::exchange(toolPick_, std::nullopt);
    Json picked = pickTool(*session_, full_, at, kind);
    stream_.submitText(Json{{"t", "picked"}, {"pick", picked}}.dump());
    if (kind) sendMeasurements();
  }
  if (vertexMove_) {
    const auto [from, to] = *std::exchange(vertexMove_, std::nullopt);
    stream_.submitText(Json{{"t", "moved"}, {"moved", moveVertexTool(*session_, full_, from, to)}}.dump());
    sendMeasurements();
  }
  if (wheel_ != 0) {
    zoomAtCursor(*session_, full_, wheelAt_, std::exchange(wheel_, 0.0));
  }
  Requests r = session_->takeRequests();
  if (r.pick) {
    std::optional<glm::dvec3> point = pickPivot(*session_, full_, *r.pick);
    stream_.submitText(
        Json{{"t", "pick"}, {"hit", point.has_value()}, {"pivot", vec(session_->pivot())}}.dump());
    stateChanged_ = true;
  }
  if (r.printCamera)
    stream_.submitText(Json{{"t", "camera"},
                            {"text", describeView(session_->camera(), session_->settings())},
                            {"options", describeSettings(session_->settings())}}
                           .dump());
  if (r.screenshot) sendScreenshot();
  // r.quit: a client closes its tab, it does not stop the server.
}

void WebClient::sendScreenshot() {
  Viewport v = session_->viewport();
  std::vector<uint32_t> rgba =
      full_.screenshot(session_->camera(), session_->settings(), v, session_->options().supersample);
  std::vector<uint8_t> png = io::encodePng(v.width, v.height, rgba.data());
  FrameHeader h;
  h.magic = kScreenshotMagic;
  h.seq = seq_;
  h.width = h.viewWidth = uint16_t(v.width);
  h.height = h.viewHeight = uint16_t(v.height);
  std::vector<uint8_t> message(kFrameHeaderBytes + png.size());
  writeFrameHeader(h, message.data());
  std::copy(png.begin(), png.end(), message.begin() + kFrameHeaderBytes);
  stream_.submitBinary(std::move(message));
  session_->invalidate(); // a supersampled shot drew with another renderer; the shown frame is redrawn
}

std::optional<double> WebClient::step(double now) {
  if (!session_) return std::nullopt;
  double elapsed = lastStep_ < 0 ? 0 : now - lastStep_;
  lastStep_ = now;
  serveRequests();
  session_->advance(elapsed);
  if (stream_.wantsFrame()) {
    bool needed = session_->needsFrame();
    if (needed || quality_.refineDue(now))
      renderFrame(now, needed ? quality_.next(session_->camera(), now) : FrameQuality::Full);
  }
  if (stateChanged_) {
    stream_.submitState(stateJson(nullptr));
    stateChanged_ = false;
  }
  // Held fly keys, or octree nodes still arriving: draw again soon.
  if (session_->animating() || full_.changedSinceLastFrame()) return now + kFlyStepSeconds;
  return quality_.refineAt();
}

void WebClient::renderFrame(double now, FrameQuality quality) {
  auto start = std::chrono::steady_clock::now();
  inputWaitMs_ = inputSince_ ? std::max(0.0, now - *std::exchange(inputSince_, std::nullopt)) * 1e3 : 0.0;
  Viewport viewport = session_->viewport();
  bool cheap = quality == FrameQuality::Motion && settings_.motionScale < 1.0;
  Viewport size = cheap ? scaleViewport(viewport, settings_.motionScale) : viewport;
  SceneView& view = cheap ? motion_ : full_;
  FrameReport report = view.render(session_->camera(), session_->settings(), size);
  RawFrame frame;
  frame.rgba = view.renderer().image();
  if (!session_->measurements().all().items.empty())
    view.drawOverlay(session_->camera(), session_->settings(), size, session_->measurements().complete(),
                     frame.rgba);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  frameWallMs_ = report.seconds * 1e3;
  session_->frameRendered(report);
  quality_.rendered(session_->camera(), quality, now);

  FrameHeader& h = frame.header;
  h.frame = nextFrame_++;
  h.seq = seq_;
  h.width = uint16_t(view.renderer().width()); // a stereo frame of odd width is a column short
  h.height = uint16_t(view.renderer().height());
  h.viewWidth = uint16_t(viewport.width);
  h.viewHeight = uint16_t(viewport.height);
  h.flags = quality == FrameQuality::Full ? kFrameFull : 0;
  h.renderMs = float(report.renderMs);
  frame.jpeg.quality = quality == FrameQuality::Full ? settings_.quality : settings_.motionQuality;
  frame.jpeg.fullChroma = quality == FrameQuality::Full;
  frame.jpeg.fastDct = quality == FrameQuality::Motion;
  stream_.submitState(stateJson(&h));
  stateChanged_ = false;
  stream_.submitFrame(std::move(frame));
}

std::string WebClient::stateJson(const FrameHeader* frame) const {
  const Session& s = *session_;
  const Statistics& st = s.statistics();
  StreamStats ss = stream_.stats();
  const Camera& c = s.camera();
  Json stats = {{"frames", st.frames},
                {"renderMs", st.renderMs},
                {"hostMs", st.hostMs},
                {"points", st.points},
                {"pointsPerSecond", st.renderMs > 0 ? double(st.points) / (st.renderMs * 1e-3) : 0.0},
                {"gpuBytes", st.gpuBytes},
                {"encodeMs", ss.encodeMs},
                {"framesPerSecond", ss.framesPerSecond},
                {"motionBytes", ss.motionBytes},
                {"fullBytes", ss.fullBytes},
                {"framesSent", ss.framesSent},
                {"framesDropped", ss.framesDropped},
                {"inputWaitMs", inputWaitMs_},
                {"frameWallMs", frameWallMs_}};
  if (st.batch)
    stats["batch"] = {{"batchesProcessed", st.batch->batchesProcessed},
                      {"batchesRendered", st.batch->batchesRendered},
                      {"pointsRendered", st.batch->pointsRendered}};
  if (st.post)
    stats["post"] = {
        {"splatMs", st.post->splatMs}, {"dilateMs", st.post->dilateMs}, {"composeMs", st.post->composeMs}};
  if (st.lod) {
    const lod::LodStats& l = *st.lod;
    stats["lod"] = {{"nodesSelected", l.nodesSelected},
                    {"pointsSelected", l.pointsSelected},
                    {"nodesDrawn", l.nodesDrawn},
                    {"pointsDrawn", l.pointsDrawn},
                    {"budgetReached", l.budgetReached},
                    {"passes", l.passes},
                    {"converged", l.converged},
                    {"nodesLoaded", l.nodesLoaded},
                    {"nodesEvicted", l.nodesEvicted},
                    {"bytesStreamed", l.bytesStreamed},
                    {"residentBytes", l.residentBytes},
                    {"cacheBytes", l.cacheBytes},
                    {"bytesPerSecond", st.streamedBytesPerSecond}};
  }
  if (!st.status.empty()) stats["status"] = st.status;
  Json j = {
      {"t", "state"},
      {"seq", seq_},
      {"viewport", {s.viewport().width, s.viewport().height}},
      {"camera", {{"eye", vec(c.eye)}, {"target", vec(c.target)}, {"up", vec(c.up)}, {"fov", c.fovY}}},
      {"pivot", vec(s.pivot())},
      {"bounds", {{"min", vec(s.navigation().bounds().min)}, {"max", vec(s.navigation().bounds().max)}}},
      {"settings", settingsJson(s.settings())},
      {"options",
       {{"panel", s.options().panel},
        {"supersample", s.options().supersample},
        {"keyframeSeconds", s.options().keyframeSeconds}}},
      {"stream",
       {{"motionScale", settings_.motionScale},
        {"quality", settings_.quality},
        {"motionQuality", settings_.motionQuality}}},
      {"keyframes",
       {{"count", session_->path().keyframes().size()}, {"duration", session_->path().duration()}}},
      {"stats", stats}};
  // The frame this state goes with: the one it precedes, else the last one sent.
  j["frame"] = frame ? frame->frame : nextFrame_ - 1;
  return j.dump();
}

} // namespace pointrast::view::web
