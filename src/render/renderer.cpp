#include "render/renderer.h"
#include "render/batch_stats.h"

#include <algorithm>
#include <cassert>
#include <cstring>

#include "base/error.h"
#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/timer.h"
#include "render/clip_volumes.h"
#include "render/lod/lod_render.h"
#include "render/method.h"
#include "render/post/post_stage.h"

namespace pointrast {

namespace {

// What each MethodNeeds flag asks of the device, and how a refusal names it.
struct NeedCheck {
  MethodNeeds need;
  bool gpu::DeviceFeatures::*present;
  const char* what;
};
constexpr NeedCheck kNeedChecks[] = {
    {MethodNeeds::Subgroups, &gpu::DeviceFeatures::subgroupCompute,
     "subgroup vote, ballot, shuffle and arithmetic in compute shaders"},
    {MethodNeeds::PartitionedNV, &gpu::DeviceFeatures::subgroupPartitionedNV,
     "VK_NV_shader_subgroup_partitioned (NVIDIA GPUs)"},
};

// 16384 x 16384 pixels: 2 GiB of framebuffer words, the most a single allocation is guaranteed to hold
// on common devices.
constexpr uint32_t kMaxSide = 16384;

} // namespace

DepthMode parseDepthMode(std::string_view name) {
  if (name == "float") return DepthMode::Float;
  if (name == "int40") return DepthMode::Int40;
  throw InputError("unknown depth encoding '" + std::string(name) + "'; choose float or int40");
}

uint32_t parsePrecision(std::string_view text) {
  if (text == "adaptive") return 0;
  if (text == "1" || text == "2" || text == "3") return uint32_t(text[0] - '0');
  throw InputError("unknown precision '" + std::string(text) +
                   "'; choose adaptive, 1, 2 or 3 (coordinate words per point; 3 = full 30 bits)");
}

const char* depthModeName(DepthMode mode) {
  return mode == DepthMode::Int40 ? "int40" : "float";
}

shared::ResolvePush resolvePush(const Frame& frame, const Targets& targets, uint64_t framebuffer,
                                uint32_t groupSize) {
  shared::ResolvePush push{};
  push.framebuffer = framebuffer;
  push.image = targets.image.address();
  const bool post = frame.settings.post.enabled();
  push.words = frame.settings.captureWords || post ? targets.words.address() : 0;
  // The resolve stage reads float depths: int40 words are converted for it.
  if (post && frame.settings.depth == DepthMode::Int40) push.int40Scale = float(frame.settings.depthScale);
  push.width = targets.width;
  push.height = targets.height;
  push.background = frame.settings.background;
  push.groupsX = gpu::gridFor(targets.pixels(), groupSize).x;
  return push;
}

double int40Scale(std::span<const GpuScene* const> scenes, const Camera& camera) {
  double farthest = 0;
  for (const GpuScene* scene : scenes) {
    const Bounds& b = scene->bounds();
    if (b.empty()) continue;
    for (int i = 0; i < 8; ++i) {
      glm::dvec3 corner{i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z};
      farthest = std::max(farthest, glm::length(corner - camera.eye));
    }
  }
  // The linear depth of a point never exceeds its distance from the eye; 1 % headroom for rounding.
  return double(shared::kInt40MaxDepth) / std::max(farthest * 1.01, 1e-9);
}

bool Renderer::supports(gpu::Context& context, Method method, std::string* why) {
  const gpu::DeviceFeatures& f = context.features();
  std::string missing;
  for (const NeedCheck& check : kNeedChecks)
    if (hasNeed(method.info().needs, check.need) && !(f.*check.present))
      missing += (missing.empty() ? "" : " and ") + std::string(check.what);
  if (!missing.empty() && why)
    *why = std::string(method.name()) + " is not available on '" + context.info().name + "': it needs " +
           missing;
  return missing.empty();
}

Renderer::Renderer(gpu::Context& context, uint32_t width, uint32_t height, uint32_t eyes)
    : context_(context), targets_(std::make_unique<Targets>()) {
  assert((eyes == 1 || eyes == 2) && "mono or stereo");
  if (width == 0 || height == 0 || width * eyes > kMaxSide || height > kMaxSide)
    throw InputError("image size " + std::to_string(width * eyes) + "x" + std::to_string(height) +
                     " is out of range (1.." + std::to_string(kMaxSide) + " per side)");
  Targets& t = *targets_;
  t.width = width * eyes;
  t.height = height;
  t.eyes = eyes;
  t.framebuffer =
      gpu::Buffer(context, t.pixels() * 8, gpu::kBufferUsage, gpu::MemoryKind::Device, "framebuffer");
  t.image = gpu::Buffer(context, t.pixels() * 4, gpu::kBufferUsage, gpu::MemoryKind::Device, "image");
}

Renderer::~Renderer() = default;

uint32_t Renderer::width() const {
  return targets_->width;
}
uint32_t Renderer::height() const {
  return targets_->height;
}
uint32_t Renderer::eyes() const {
  return targets_->eyes;
}

std::vector<Camera> Renderer::views(const Camera& camera, const RenderSettings& settings) const {
  const Targets& t = *targets_;
  if (t.eyes == 1) return {camera};
  validateStereo(settings.stereo);
  const double aspect = double(t.eyeWidth()) / double(t.height);
  std::vector<Camera> eyes;
  for (uint32_t half = 0; half < 2; ++half)
    eyes.push_back(eyeCamera(camera, settings.stereo, eyeOfHalf(settings.stereo, half), aspect));
  return eyes;
}

PointMethod& Renderer::method(const RenderSettings& settings) {
  const MethodInfo& info = methodInfo(settings.method);
  if (settings.depth == DepthMode::Int40 && !info.int40Shader)
    throw InputError(std::string(info.name) + " has no int40 depth encoding, only float");
  if (settings.depth == DepthMode::Int40 && !context_.features().float64)
    throw UnsupportedError("the int40 depth encoding needs double precision in shaders (shaderFloat64), "
                           "which '" +
                           context_.info().name + "' lacks");
  std::string why;
  if (!supports(context_, settings.method, &why)) throw UnsupportedError(why);
  if (targets_->eyes == 2 && info.family != MethodFamily::Batch)
    throw InputError(
        std::string("stereo frames draw both eyes in one pass with the batch and LOD methods (") +
        methodNamesReading(SceneLayout::Batched) + ", " + methodNamesReading(SceneLayout::Octree) +
        "), not " + info.name);
  auto key = std::make_pair(settings.method, settings.depth);
  auto found = methods_.find(key);
  if (found != methods_.end()) return *found->second;
  std::unique_ptr<PointMethod> created;
  switch (info.family) {
  case MethodFamily::Closest:
  case MethodFamily::BusyLoop:
    created = createClosestMethod(context_, info, settings.depth);
    break;
  case MethodFamily::Hqs:
    created = createHqsMethod(context_, info, targets_->width, targets_->height);
    break;
  case MethodFamily::HwPoints:
    created = createHwPointsMethod(context_, info, targets_->width, targets_->height);
    break;
  case MethodFamily::Batch:
    created = createBatchMethod(context_, info, targets_->width, targets_->height, targets_->eyes);
    break;
  case MethodFamily::Lod:
    throw InputError(std::string(info.name) +
                     " draws octrees streamed from a node source, not uploaded scenes");
  }
  return *methods_.emplace(key, std::move(created)).first->second;
}

FrameStats Renderer::render(std::span<const GpuScene* const> scenes, const Camera& camera,
                            const RenderSettings& settings) {
  validateCamera(camera);
  const MethodInfo& info = methodInfo(settings.method);
  size_t parts = 0;
  for (const GpuScene* scene : scenes) {
    if (scene->layout() != info.layout)
      throw InputError(std::string(info.name) + " reads scenes in the " + sceneLayoutName(info.layout) +
                       " layout, but a scene was uploaded in the " + sceneLayoutName(scene->layout()) +
                       " layout (UploadOptions::layout)");
    parts += scene->parts().size();
  }
  if (info.layout == SceneLayout::Batched && parts > shared::kMaxVisibilityParts)
    throw InputError("the scenes have " + std::to_string(parts) + " parts; the batch methods draw at most " +
                     std::to_string(shared::kMaxVisibilityParts) +
                     " per frame (parts of up to 67,102,720 points: 4.29 billion points, the reach of a "
                     "32-bit visibility index)");
  if (settings.precision > 3) throw InputError("precision must be 0 (adaptive) or 1..3 words");
  const bool post = preparePost(settings);
  PointMethod& m = method(settings);
  if (settings.hqsPass != HqsPass::Whole && !m.blends())
    throw InputError(std::string(info.name) +
                     " records whole frames; HQS steps are for hqs, hqs1r, batch-hqs and lod-hqs");
  last_ = &m;
  lodHqs_ = nullptr;
  Targets& t = *targets_;
  if (settings.captureWords) allocateWords();
  // Each scene's record: its clip volumes and the double-precision copy of its matrix (the int40 path).
  std::vector<glm::dvec3> origins;
  for (const GpuScene* scene : scenes)
    origins.push_back(scene->origin());
  writeSceneTable(origins, settings);
  const std::vector<Camera> eyes = views(camera, settings);
  double aspect = double(t.eyeWidth()) / double(t.height);
  char* table = static_cast<char*>(t.scenes.mapped());
  uint32_t part = 0;
  for (size_t s = 0; s < scenes.size(); ++s) {
    glm::dmat4 vp = viewProjection(eyes[0], scenes[s]->origin(), aspect);
    std::memcpy(table + sceneRecordOffset(s) + shared::kSceneMatrixOffset, &vp, sizeof vp);
    // The batch passes find a part's clip volumes by its visibility part number.
    for (size_t p = 0; p < scenes[s]->parts().size() && part < shared::kMaxVisibilityParts; ++p, ++part) {
      const uint64_t clip = t.scenes.address() + sceneRecordOffset(s);
      std::memcpy(table + 8 * part, &clip, sizeof clip);
    }
  }
  RenderSettings effective = settings;
  if (effective.depth == DepthMode::Int40 && effective.depthScale <= 0)
    effective.depthScale = int40Scale(scenes, camera);
  uint32_t frames = std::max(1u, settings.frames);
  gpu::TimestampPool timestamps(context_, frames);
  const std::vector<PostView> eyeViews = postViews(camera, settings);
  std::optional<gpu::TimestampPool> postTimestamps;
  if (post) postTimestamps.emplace(context_, frames * kPostPasses);
  context_.submitAndWait([&](VkCommandBuffer cmd) {
    timestamps.reset(cmd);
    if (post) postTimestamps->reset(cmd);
    Frame frame{cmd, scenes, camera, effective, eyes};
    frame.counted = false;
    for (uint32_t w = 0; w < settings.warmup; ++w) {
      m.recordFrame(frame, t);
      if (post) post_->record(cmd, eyeViews, settings.post);
    }
    for (uint32_t f = 0; f < frames; ++f) {
      frame.counted = f + 1 == frames; // the counts (FrameStats::batch) are the last timed frame's
      timestamps.begin(cmd, f);
      m.recordFrame(frame, t);
      if (post) post_->record(cmd, eyeViews, settings.post, &*postTimestamps, f * kPostPasses);
      timestamps.end(cmd, f);
    }
  });
  wordsCaptured_ = settings.captureWords && (hasCanonicalWords(info) || post);
  std::vector<double> ms = timestamps.milliseconds();
  FrameStats stats;
  stats.frames = frames;
  stats.medianMs = gpu::median(ms);
  stats.minMs = *std::min_element(ms.begin(), ms.end());
  stats.maxMs = *std::max_element(ms.begin(), ms.end());
  for (const GpuScene* scene : scenes)
    stats.points += scene->pointCount();
  stats.batch = m.readStats();
  if (post) stats.post = PostStage::stats(postTimestamps->milliseconds(), frames);
  return stats;
}

lod::LodPasses& Renderer::lodPasses(const RenderSettings& settings) {
  const MethodInfo& info = methodInfo(settings.method);
  if (info.layout != SceneLayout::Octree)
    throw InputError(std::string(info.name) + " reads scenes in the " + sceneLayoutName(info.layout) +
                     " layout, not octrees; the LOD methods are " + methodNamesReading(SceneLayout::Octree));
  if (settings.depth != DepthMode::Float)
    throw InputError(std::string(info.name) + " has no int40 depth encoding, only float");
  if (settings.precision > 3) throw InputError("precision must be 0 (adaptive) or 1..3 words");
  std::string why;
  if (!supports(context_, settings.method, &why)) throw UnsupportedError(why);
  auto found = lodPasses_.find(settings.method);
  if (found != lodPasses_.end()) return *found->second;
  auto created =
      std::make_unique<lod::LodPasses>(context_, info, targets_->width, targets_->height, targets_->eyes);
  return *lodPasses_.emplace(settings.method, std::move(created)).first->second;
}

bool Renderer::preparePost(const RenderSettings& settings) {
  if (!settings.post.enabled()) return false;
  validatePostSettings(settings.post);
  const MethodInfo& info = methodInfo(settings.method);
  if (info.output == MethodOutput::ColorOnly)
    throw InputError(std::string("point size, dilation and eye-dome lighting work on the depth the "
                                 "compute methods keep per pixel; ") +
                     info.name + " keeps none");
  allocateWords(); // what the method's resolve hands the stage
  if (!post_) post_ = std::make_unique<PostStage>(context_);
  return true;
}

void Renderer::allocateWords() {
  // Canonical words are for equivalence tests and the resolve stage: allocated on first request (8 B a
  // pixel).
  Targets& t = *targets_;
  if (!t.words)
    t.words =
        gpu::Buffer(context_, t.pixels() * 8, gpu::kBufferUsage, gpu::MemoryKind::Device, "canonical words");
}

std::vector<PostView> Renderer::postViews(const Camera& camera, const RenderSettings& settings) const {
  if (!settings.post.enabled()) return {};
  const Targets& t = *targets_;
  std::vector<PostView> views;
  // Each eye is a window of the side-by-side buffers.
  for (uint32_t e = 0; e < t.eyes; ++e)
    views.push_back({t.words.address() + uint64_t(e) * t.eyeWidth() * 8,
                     t.image.address() + uint64_t(e) * t.eyeWidth() * 4, t.eyeWidth(), t.height, t.width,
                     float(glm::length(camera.target - camera.eye)), settings.background,
                     settings.captureWords});
  return views;
}

void Renderer::writeSceneTable(std::span<const glm::dvec3> origins, const RenderSettings& settings) {
  Targets& t = *targets_;
  const uint64_t bytes = sceneRecordOffset(std::max<size_t>(1, origins.size()));
  if (!t.scenes || t.scenes.size() < bytes)
    t.scenes = gpu::Buffer(context_, bytes, gpu::kBufferUsage, gpu::MemoryKind::Upload, "scene table");
  char* table = static_cast<char*>(t.scenes.mapped());
  std::memset(table, 0, bytes);
  for (size_t s = 0; s < std::max<size_t>(1, origins.size()); ++s) {
    const shared::ClipVolumes clip =
        gpuClipVolumes(settings.filter, s < origins.size() ? origins[s] : glm::dvec3(0));
    std::memcpy(table + sceneRecordOffset(s), &clip, sizeof clip);
  }
}

FrameStats Renderer::renderLod(lod::LodScene& octree, const Camera& camera, const RenderSettings& settings,
                               bool resident) {
  validateCamera(camera);
  lod::LodPasses& passes = lodPasses(settings);
  if (settings.hqsPass != HqsPass::Whole && !passes.hqs())
    throw InputError(std::string(methodName(settings.method)) +
                     " records whole frames; HQS steps are for hqs, hqs1r, batch-hqs and lod-hqs");
  const bool post = preparePost(settings);
  Targets& t = *targets_;
  if (settings.captureWords) allocateWords();
  // The resolve stage after the passes of each frame, timed per pass as in render().
  const std::vector<PostView> eyeViews = postViews(camera, settings);
  std::optional<gpu::TimestampPool> postTimestamps;
  uint32_t postFrames = 0;
  lod::FrameEpilogue epilogue;
  if (post) {
    epilogue.begin = [&](VkCommandBuffer cmd, uint32_t timedFrames) {
      postFrames = timedFrames;
      postTimestamps.emplace(context_, timedFrames * kPostPasses);
      postTimestamps->reset(cmd);
    };
    epilogue.record = [&](VkCommandBuffer cmd, uint32_t frame) {
      if (frame == lod::FrameEpilogue::kUntimed)
        post_->record(cmd, eyeViews, settings.post);
      else
        post_->record(cmd, eyeViews, settings.post, &*postTimestamps, frame * kPostPasses);
    };
  }
  const glm::dvec3 origin = octree.origin();
  writeSceneTable({&origin, 1}, settings); // LodFrame::clip is the first record's
  const std::vector<Camera> eyes = views(camera, settings);
  FrameStats stats = resident
                         ? lod::renderResidentFrame(context_, octree, passes, t, eyes, settings, epilogue)
                         : lod::renderOctree(context_, octree, passes, t, eyes, settings, epilogue);
  if (post) stats.post = PostStage::stats(postTimestamps->milliseconds(), postFrames);
  wordsCaptured_ = settings.captureWords && (hasCanonicalWords(methodInfo(settings.method)) || post);
  last_ = nullptr;
  lodHqs_ = passes.hqs() ? &passes : nullptr;
  pickableOctree_ = nullptr;
  if (t.eyes != 1)
    lodWhy_ = "a stereo frame shows two cameras";
  else if (methodInfo(settings.method).output != MethodOutput::Closest)
    lodWhy_ = "only the lod method keeps the point drawn at each pixel";
  else if (stats.lod && stats.lod->passes != 1)
    lodWhy_ = "the selection was larger than the node cache and drawn in passes (raise --gpu-memory)";
  else
    pickableOctree_ = &octree;
  return stats;
}

FrameStats Renderer::render(lod::LodScene& octree, const Camera& camera, const RenderSettings& settings) {
  return renderLod(octree, camera, settings, false);
}

FrameStats Renderer::renderFrame(lod::LodScene& octree, const Camera& camera,
                                 const RenderSettings& settings) {
  return renderLod(octree, camera, settings, true);
}

std::optional<Renderer::LodPixel> Renderer::lodPointAt(uint32_t x, uint32_t y) {
  assert(x < targets_->width && y < targets_->height && "outside the image");
  if (!pickableOctree_) throw InputError(lodWhy_);
  // The lod pass's visibility word: float depth << 32 | the point's index in the pass (shared.h, LodNode).
  uint64_t word = 0;
  gpu::readBuffer(context_, targets_->framebuffer, (uint64_t(y) * targets_->width + x) * 8, &word, 8);
  if (word == shared::kEmptyPixel) return std::nullopt;
  const uint32_t index = uint32_t(word);
  const lod::LodDrawList& list = pickableOctree_->drawList();
  const std::vector<uint32_t>& ids = pickableOctree_->drawnNodes();
  // The last node whose first index is <= index, as resolve_lod.comp.glsl finds it.
  auto after = std::upper_bound(list.nodes.begin(), list.nodes.end(), index,
                                [](uint32_t i, const shared::LodNode& n) { return i < n.firstIndex; });
  if (after == list.nodes.begin()) return std::nullopt;
  const size_t k = size_t(after - list.nodes.begin()) - 1;
  if (k >= ids.size() || index - list.nodes[k].firstIndex >= list.nodes[k].pointCount) return std::nullopt;
  return LodPixel{ids[k], index - list.nodes[k].firstIndex};
}

std::vector<uint32_t> Renderer::image() {
  std::vector<uint32_t> pixels(targets_->pixels());
  gpu::readBuffer(context_, targets_->image, 0, pixels.data(), pixels.size() * 4);
  return pixels;
}

void Renderer::showComposite(std::span<const uint32_t> image, std::span<const uint64_t> words) {
  Targets& t = *targets_;
  assert(image.size() == t.pixels() && words.size() == t.pixels() && "a composited frame of this size");
  allocateWords();
  gpu::writeBuffer(context_, t.image, 0, image.data(), image.size_bytes());
  gpu::writeBuffer(context_, t.words, 0, words.data(), words.size_bytes());
  wordsCaptured_ = true;
  last_ = nullptr;
  lodHqs_ = nullptr;
  pickableOctree_ = nullptr;
  lodWhy_ = "the last frame was composited from several processes' frames";
}

std::vector<uint64_t> Renderer::framebufferWords() {
  std::vector<uint64_t> words(targets_->pixels());
  framebufferWords(words);
  return words;
}

void Renderer::framebufferWords(std::span<uint64_t> into) {
  if (!wordsCaptured_)
    throw InputError("no canonical framebuffer words: the last frame was not rendered with captureWords by a "
                     "closest-point method");
  if (into.size() != targets_->pixels())
    throw InputError("framebuffer words: the destination is not the image's size");
  gpu::readBuffer(context_, targets_->words, 0, into.data(), into.size() * 8, &wordsReadback_);
}

std::vector<uint64_t> Renderer::framebufferWords(uint32_t x, uint32_t y, uint32_t w, uint32_t h) {
  assert(uint64_t(x) + w <= targets_->width && uint64_t(y) + h <= targets_->height && "outside the image");
  if (!wordsCaptured_)
    throw InputError("no canonical framebuffer words: the last frame was not rendered with captureWords by a "
                     "closest-point method");
  std::vector<uint64_t> words(uint64_t(w) * h);
  for (uint32_t row = 0; row < h; ++row)
    gpu::readBuffer(context_, targets_->words, ((uint64_t(y) + row) * targets_->width + x) * 8,
                    words.data() + uint64_t(row) * w, uint64_t(w) * 8);
  return words;
}

namespace {
PointMethod& blending(PointMethod* last) {
  if (!last || !last->blends())
    throw InputError("no HQS buffers: the last frame was not rendered with an HQS method");
  return *last;
}
} // namespace

std::vector<uint64_t> Renderer::hqsDepths() {
  if (!lodHqs_) blending(last_);
  std::vector<uint64_t> words(targets_->pixels());
  gpu::readBuffer(context_, targets_->framebuffer, 0, words.data(), words.size() * 8);
  return words;
}

void Renderer::setHqsDepths(std::span<const uint64_t> words) {
  if (!lodHqs_) blending(last_);
  if (words.size() != targets_->pixels()) throw InternalError("internal error: depths of another image size");
  gpu::writeBuffer(context_, targets_->framebuffer, 0, words.data(), words.size() * 8);
}

std::vector<uint64_t> Renderer::hqsSums() {
  return lodHqs_ ? lodHqs_->readSums() : blending(last_).readSums();
}

void Renderer::setHqsSums(std::span<const uint64_t> sums) {
  if (lodHqs_)
    lodHqs_->writeSums(sums);
  else
    blending(last_).writeSums(sums);
}

uint64_t Renderer::imageAddress() const {
  return targets_->image.address();
}

BatchStats batchStatsFromRows(const uint64_t (&rows)[shared::kBatchStatSlots][shared::kBatchStatCount],
                              bool hqs) {
  uint64_t sum[shared::kBatchStatCount] = {};
  for (const auto& row : rows)
    for (uint32_t k = 0; k < shared::kBatchStatCount; ++k)
      sum[k] += row[k];
  BatchStats s;
  s.batchesProcessed = sum[shared::kStatBatchesProcessed];
  s.batchesRendered = sum[shared::kStatBatchesRendered];
  s.pointsRendered = sum[shared::kStatPointsRendered];
  s.pointsBlended = sum[shared::kStatPointsBlended];
  for (int w = 0; w < 3; ++w) {
    s.pointsByWords[w] = sum[shared::kStatPointsOneWord + w];
    s.pointsProcessed += s.pointsByWords[w];
  }
  s.batchesDense = sum[shared::kStatBatchesDense];
  s.pointsTakenBack = sum[shared::kStatPointsTakenBack];
  s.batchesRedrawn = sum[shared::kStatBatchesRedrawn];
  s.batchesClipped = sum[shared::kStatBatchesClipped];
  // Every batch (or octree node) reads its bounds, every point of a drawn one its words.
  const uint64_t once = s.batchesProcessed * sizeof(shared::BatchBounds) +
                        4 * (s.pointsByWords[0] + 2 * s.pointsByWords[1] + 3 * s.pointsByWords[2]);
  // HQS: the accumulation pass reads the words again, but not those of dense batches (one word a point)
  // unless it draws them again; colors are read for every blended point, and for a dense batch's points
  // taken back twice.
  const uint64_t denseWords = 4 * uint64_t(shared::kBatchPoints) * (s.batchesDense - s.batchesRedrawn);
  s.bytesRead = hqs ? 2 * once - denseWords + 4 * (s.pointsBlended + s.pointsTakenBack) : once;
  return s;
}

} // namespace pointrast
