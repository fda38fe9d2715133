#include "view/scene_view.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <chrono>
#include <cmath>

#include "base/error.h"
#include "cloud/cloud.h"
#include "gpu/context.h"
#include "render/overlay.h"
#include "render/pick.h"
#include "render/scene.h"
#include "report/pick_json.h"

namespace pointrast::view {

namespace {

// Where picking reads canonical words: the current method when it writes them with float depth, else the
// plain closest-point method of the same scene layout.
RenderSettings pickSettings(const ViewSettings& view) {
  RenderSettings settings = renderSettings(view);
  const MethodInfo& info = methodInfo(view.method);
  if (info.output != MethodOutput::Closest)
    settings.method = info.layout == SceneLayout::Octree    ? pointMethod("lod")
                      : info.layout == SceneLayout::Batched ? pointMethod("batch")
                                                            : pointMethod("atomicmin");
  settings.depth = DepthMode::Float;
  settings.captureWords = true;
  return settings;
}

constexpr uint64_t kEmptyWord = ~0ull;

} // namespace

RenderSettings renderSettings(const ViewSettings& requested) {
  const ViewSettings view = applicable(requested);
  RenderSettings settings;
  settings.method = view.method;
  settings.background = view.background;
  settings.depth = view.depth;
  settings.post = view.post;
  settings.minNodePx = view.minNodePx;
  settings.pointBudget = view.pointBudget;
  settings.filter = view.filter;
  settings.stereo = view.eyes;
  settings.foveation = view.foveation;
  settings.frames = 1;
  settings.warmup = 0;
  return settings;
}

std::vector<uint32_t> boxDownsample(std::span<const uint32_t> rgba, uint32_t width, uint32_t height,
                                    uint32_t factor) {
  assert(factor > 0 && width % factor == 0 && height % factor == 0 &&
         rgba.size() == uint64_t(width) * height);
  uint32_t w = width / factor, h = height / factor;
  std::vector<uint32_t> out(uint64_t(w) * h);
  uint32_t count = factor * factor;
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      uint32_t sum[4] = {0, 0, 0, 0};
      for (uint32_t dy = 0; dy < factor; ++dy)
        for (uint32_t dx = 0; dx < factor; ++dx) {
          uint32_t p = rgba[(uint64_t(y) * factor + dy) * width + uint64_t(x) * factor + dx];
          for (int c = 0; c < 4; ++c)
            sum[c] += (p >> (8 * c)) & 0xFF;
        }
      uint32_t pixel = 0;
      for (int c = 0; c < 4; ++c)
        pixel |= ((sum[c] + count / 2) / count) << (8 * c);
      out[uint64_t(y) * w + x] = pixel;
    }
  return out;
}

GpuCloud::GpuCloud(gpu::Context& context, const PointCloud& cloud, bool progress)
    : context_(context), cloud_(cloud), progress_(progress) {}

GpuCloud::~GpuCloud() = default;

const GpuScene& GpuCloud::scene(SceneLayout layout) {
  if (layout == SceneLayout::Octree)
    throw InputError("the LOD methods draw octrees streamed from disk, not an uploaded cloud");
  std::unique_ptr<GpuScene>& slot = scenes_[int(layout)];
  if (!slot) {
    UploadOptions upload;
    upload.layout = layout;
    upload.progress = progress_;
    upload.colors = colors_;
    slot = std::make_unique<GpuScene>(context_, cloud_, upload);
  }
  return *slot;
}

std::optional<std::string> GpuCloud::setColors(std::optional<DisplayColorMode::Source> source,
                                               std::optional<ColorRange> range) {
  auto sameRange = [](const std::optional<ColorRange>& a, const std::optional<ColorRange>& b) {
    return a.has_value() == b.has_value() && (!a || (a->lo == b->lo && a->hi == b->hi));
  };
  if (source == colorSource_ && sameRange(range, colorRange_)) return std::nullopt;
  std::optional<DisplayColorMode> mode;
  try {
    mode = source ? displayColorMode(cloud_, *source, range) : displayColorMode(cloud_);
  } catch (const InputError& e) {
    return e.what();
  }
  colorSource_ = source;
  colorRange_ = range;
  colors_ = mode;
  for (auto& scene : scenes_)
    if (scene) scene->recolor(context_, cloud_, *mode);
  return std::nullopt;
}

void GpuCloud::setColors(std::optional<DisplayColorMode::Source> source, std::optional<ColorRange> range,
                         const DisplayColorMode& mode) {
  const bool same =
      colors_ && colors_->source == mode.source && colors_->lo == mode.lo && colors_->hi == mode.hi;
  colorSource_ = source;
  colorRange_ = range;
  colors_ = mode;
  if (same) return;
  for (auto& scene : scenes_)
    if (scene) scene->recolor(context_, cloud_, mode);
}

const std::string& GpuCloud::name() const {
  return cloud_.source;
}

FrameStats GpuCloud::draw(Renderer& renderer, const Camera& camera, const RenderSettings& rs,
                          const ViewSettings& settings, std::string& status) {
  if (std::optional<std::string> why = setColors(settings.colorSource, settings.colorRange)) status = *why;
  return renderer.render(scene(methodInfo(rs.method).layout), camera, rs);
}

DisplayColorMode GpuCloud::colors() const {
  return colors_ ? *colors_ : displayColorMode(cloud_);
}

const Bounds& GpuCloud::bounds() const {
  return cloud_.bounds;
}

uint64_t GpuCloud::pointCount() const {
  return cloud_.size();
}

uint64_t GpuCloud::bytes() const {
  uint64_t bytes = 0;
  for (const auto& s : scenes_)
    if (s) bytes += s->bytes();
  return bytes;
}

SceneView::SceneView(gpu::Context& context, SceneSource& source) : context_(context), source_(source) {}

SceneView::~SceneView() = default;

uint64_t SceneView::gpuBytes() const {
  uint64_t bytes = source_.bytes();
  // Framebuffer (8 B), image (4 B) and, once a pick asked for them, canonical words (8 B) per pixel.
  if (renderer_) bytes += uint64_t(renderer_->width()) * renderer_->height() * 20;
  return bytes;
}

void SceneView::ensureRenderer(Viewport viewport, uint32_t eyes) {
  if (renderer_ && renderer_->width() == viewport.width * eyes && renderer_->height() == viewport.height &&
      renderer_->eyes() == eyes)
    return;
  renderer_.reset(); // its targets go before the new ones are allocated
  renderer_ = std::make_unique<Renderer>(context_, viewport.width, viewport.height, eyes);
}

FrameReport SceneView::render(const Camera& camera, const ViewSettings& settings, Viewport viewport) {
  auto start = std::chrono::steady_clock::now();
  // Stereo: two eyes of half the viewport each, side by side (one column short for an odd width).
  const bool stereo = applicable(settings).stereo;
  ensureRenderer(eyeViewport(settings, viewport), stereo ? 2 : 1);
  RenderSettings rs = renderSettings(settings);
  FrameReport report;
  FrameStats stats = source_.draw(*renderer_, camera, rs, settings, report.status);
  report.renderMs = stats.medianMs;
  report.points = stats.points;
  report.batch = stats.batch;
  report.post = stats.post;
  report.lod = stats.lod;
  report.gpuBytes = gpuBytes();
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

std::optional<SceneView::Picked> SceneView::pickPoint(const Camera& camera, const ViewSettings& settings,
                                                      Viewport viewport, glm::dvec2 position) {
  if (!(position.x >= 0 && position.y >= 0 && position.x < viewport.width && position.y < viewport.height))
    return std::nullopt;
  // A stereo frame shows two cameras side by side: the pivot and zoom keep to the camera's own plane.
  if (applicable(settings).stereo) return std::nullopt;
  ensureRenderer(viewport, 1);
  RenderSettings rs = pickSettings(settings);
  std::string status;
  // A frame the source could not draw (a damaged node) has no words to read: nothing is picked.
  if (source_.draw(*renderer_, camera, rs, settings, status).frames == 0) return std::nullopt;
  int px = int(position.x), py = int(position.y), r = int(kPickRadius);
  int x0 = std::max(0, px - r), y0 = std::max(0, py - r);
  int x1 = std::min(int(viewport.width) - 1, px + r), y1 = std::min(int(viewport.height) - 1, py + r);
  std::vector<uint64_t> words =
      renderer_->framebufferWords(uint32_t(x0), uint32_t(y0), uint32_t(x1 - x0 + 1), uint32_t(y1 - y0 + 1));
  std::optional<Picked> best;
  int bestDistance = 0;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      uint64_t word = words[size_t(y - y0) * size_t(x1 - x0 + 1) + size_t(x - x0)];
      if (word == kEmptyWord) continue;
      int distance = (x - px) * (x - px) + (y - py) * (y - py);
      double depth = std::bit_cast<float>(uint32_t(word >> 32));
      if (best && (distance > bestDistance || (distance == bestDistance && depth >= best->depth))) continue;
      // The point lies somewhere in its pixel: its center is within half a pixel's footprint of it.
      best = Picked{unproject(camera, viewport, {x + 0.5, y + 0.5}, depth), depth};
      bestDistance = distance;
    }
  // Picking may have drawn with another method: show the current one again.
  if (rs.method != settings.method) render(camera, settings, viewport);
  return best;
}

std::optional<glm::dvec3> SceneView::pick(const Camera& camera, const ViewSettings& settings,
                                          Viewport viewport, glm::dvec2 position) {
  auto picked = pickPoint(camera, settings, viewport, position);
  if (!picked) return std::nullopt;
  return picked->point;
}

nlohmann::json SceneView::pickAttributes(const Camera& camera, const ViewSettings& settings,
                                         Viewport viewport, glm::dvec2 position) {
  const int px = int(std::floor(position.x)), py = int(std::floor(position.y));
  if (!(position.x >= 0 && position.y >= 0 && position.x < viewport.width && position.y < viewport.height))
    return {{"pixel", {px, py}}, {"point", "none"}};
  auto unavailable = [&](const std::string& why) {
    return nlohmann::json{{"pixel", {px, py}}, {"point", "unavailable: " + why}};
  };
  if (applicable(settings).stereo) return unavailable("a stereo frame shows two cameras; turn stereo off to pick");
  if (const std::string why = source_.pointsElsewhere(); !why.empty()) return unavailable(why);
  auto* cloud = dynamic_cast<GpuCloud*>(&source_);
  auto* octree = dynamic_cast<GpuOctree*>(&source_);
  if (!cloud && !octree) return unavailable("this input keeps no points to pick from");
  ensureRenderer(viewport, 1);
  RenderSettings rs = pickSettings(settings);
  // An octree's point is read from the lod pass's visibility buffer, whose pixels the resolve stage does
  // not widen: the nearest pixel is searched in words without it.
  if (octree) rs.post = {};
  const bool redraw = rs.method != settings.method || (octree && applicable(settings).post.enabled());
  std::string status;
  if (source_.draw(*renderer_, camera, rs, settings, status).frames == 0) return unavailable(status);
  const int r = int(kPickRadius);
  const int x0 = std::max(0, px - r), y0 = std::max(0, py - r);
  const int x1 = std::min(int(viewport.width) - 1, px + r), y1 = std::min(int(viewport.height) - 1, py + r);
  const std::vector<uint64_t> words =
      renderer_->framebufferWords(uint32_t(x0), uint32_t(y0), uint32_t(x1 - x0 + 1), uint32_t(y1 - y0 + 1));
  // The nearest pixel that shows a point, the closest point where pixels tie.
  std::optional<std::pair<int, int>> best;
  uint64_t bestWord = kEmptyWord;
  int bestDistance = 0;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const uint64_t word = words[size_t(y - y0) * size_t(x1 - x0 + 1) + size_t(x - x0)];
      if (word == kEmptyWord) continue;
      const int distance = (x - px) * (x - px) + (y - py) * (y - py);
      if (best && (distance > bestDistance || (distance == bestDistance && word >= bestWord))) continue;
      best = {x, y};
      bestWord = word;
      bestDistance = distance;
    }
  const auto [bx, by] = best ? *best : std::pair<int, int>{px, py};
  if (octree && best) {
    nlohmann::json j;
    try {
      j = pickJson(*renderer_, octree->scene(), uint32_t(bx), uint32_t(by));
    } catch (const InputError& e) {
      j = unavailable(e.what());
    }
    if (redraw) render(camera, settings, viewport);
    const nlohmann::json p = j["point"];
    if (p.is_object()) j["world"] = {p["x"], p["y"], p["z"]};
    return j;
  }
  if (redraw) render(camera, settings, viewport);
  if (!best) return {{"pixel", {px, py}}, {"point", "none"}};
  PickRequest request;
  request.cloud = &cloud->cloud();
  request.colors = cloud->colors();
  request.filter = rs.filter;
  request.camera = camera;
  request.width = viewport.width;
  request.height = viewport.height;
  request.depth = DepthMode::Float;
  std::optional<uint64_t> index = pointrast::pickPoint(request, uint32_t(bx), uint32_t(by), bestWord);
  nlohmann::json j = pickJson(cloud->cloud(), uint32_t(bx), uint32_t(by), false, index);
  if (index) {
    const glm::dvec3 w = cloud->cloud().world(*index);
    j["world"] = {w.x, w.y, w.z};
  }
  return j;
}

void SceneView::drawOverlay(const Camera& camera, const ViewSettings& settings, Viewport viewport,
                            const Annotations& annotations, std::vector<uint32_t>& rgba) {
  if (annotations.items.empty() || applicable(settings).stereo) return;
  if (rgba.size() != uint64_t(viewport.width) * viewport.height) return;
  ensureRenderer(viewport, 1);
  const RenderSettings rs = pickSettings(settings);
  std::string status;
  std::vector<uint64_t> words;
  if (source_.draw(*renderer_, camera, rs, settings, status).frames > 0) words = renderer_->framebufferWords();
  const double nearW = camera.nearW > 0 ? camera.nearW : defaultNear(source_.bounds());
  drawAnnotations({rgba, viewport.width, viewport.height, words}, camera, nearW, annotations);
  if (rs.method != settings.method || rs.depth != settings.depth) render(camera, settings, viewport);
}

std::optional<double> SceneView::depthAt(const Camera& camera, const ViewSettings& settings,
                                         Viewport viewport, glm::dvec2 position) {
  auto picked = pickPoint(camera, settings, viewport, position);
  if (!picked) return std::nullopt;
  return picked->depth;
}

std::vector<uint32_t> SceneView::screenshot(const Camera& camera, const ViewSettings& settings,
                                            Viewport viewport, uint32_t supersample) {
  // An odd-width stereo frame is a column short of the viewport: the background fills it.
  auto fitted = [&](std::vector<uint32_t> pixels, uint32_t width) {
    if (width == viewport.width) return pixels;
    std::vector<uint32_t> out(uint64_t(viewport.width) * viewport.height, applicable(settings).background);
    for (uint32_t y = 0; y < viewport.height; ++y)
      std::copy_n(pixels.begin() + int64_t(y) * width, std::min(width, viewport.width),
                  out.begin() + int64_t(y) * viewport.width);
    return out;
  };
  if (supersample <= 1) {
    render(camera, settings, viewport);
    return fitted(renderer_->image(), renderer_->width());
  }
  const bool stereo = applicable(settings).stereo;
  const Viewport eye = eyeViewport(settings, viewport);
  Renderer big(context_, eye.width * supersample, eye.height * supersample, stereo ? 2 : 1);
  std::string status;
  source_.draw(big, camera, renderSettings(settings), settings, status);
  std::vector<uint32_t> pixels = big.image();
  return fitted(boxDownsample(pixels, big.width(), big.height(), supersample), big.width() / supersample);
}

void zoomAtCursor(Session& session, SceneView& view, glm::dvec2 position, double steps) {
  std::optional<double> depth =
      view.depthAt(session.camera(), session.settings(), session.viewport(), position);
  session.wheel(position, steps, depth);
}

nlohmann::json pickTool(Session& session, SceneView& view, glm::dvec2 position,
                        std::optional<AnnotationKind> measure) {
  nlohmann::json picked = view.pickAttributes(session.camera(), session.settings(), session.viewport(), position);
  if (measure && picked.contains("world")) {
    const nlohmann::json& w = picked["world"];
    session.measurements().add(*measure, {w[0].get<double>(), w[1].get<double>(), w[2].get<double>()});
    session.invalidate(); // the overlay changed
  }
  return picked;
}

nlohmann::json moveVertexTool(Session& session, SceneView& view, glm::dvec2 from, glm::dvec2 to) {
  const Camera& camera = session.camera();
  const double nearW = camera.nearW > 0 ? camera.nearW : defaultNear(view.source().bounds());
  const Viewport v = session.viewport();
  MeasureTool& tool = session.measurements();
  const auto grabbed = tool.vertexNear(camera, nearW, v.width, v.height, from, kVertexGrabPixels);
  if (!grabbed) return {{"moved", false}};
  nlohmann::json j = {{"index", grabbed->first}, {"vertex", grabbed->second}};
  j["pick"] = view.pickAttributes(camera, session.settings(), v, to);
  bool moved = false;
  if (j["pick"].contains("world")) {
    const nlohmann::json& w = j["pick"]["world"];
    moved = tool.move(grabbed->first, grabbed->second,
                      {w[0].get<double>(), w[1].get<double>(), w[2].get<double>()});
  }
  if (moved) session.invalidate(); // the overlay changed
  j["moved"] = moved;
  return j;
}

std::optional<glm::dvec3> pickPivot(Session& session, SceneView& view, glm::dvec2 position) {
  std::optional<glm::dvec3> point =
      view.pick(session.camera(), session.settings(), session.viewport(), position);
  session.pivotPicked(point);
  return point;
}

} // namespace pointrast::view
