// Draws GPU scenes with one of the methods of the four papers and resolves to an RGBA8 image. All
// closest-point methods write the same framebuffer words for the same input and camera (docs/design.md,
// "Equivalence"); they differ only in how they get there, which is what the benchmarks compare.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cloud/point_filter.h"
#include "render/camera.h"
#include "render/lod/foveation.h"
#include "render/lod/lod_stats.h"
#include "render/method_table.h"
#include "render/post/post_settings.h"
#include "render/scene.h"
#include "render/stereo.h"

namespace pointrast {

namespace gpu {
class Buffer;
class Context;
} // namespace gpu

enum class DepthMode {
  Float, // IEEE bits of the linear depth, 32 bits, color in the low 32 bits
  Int40, // 2019 poster: depth in double precision, 40-bit integer steps, color in the low 24 bits
};

DepthMode parseDepthMode(std::string_view name);
const char* depthModeName(DepthMode mode);

// The steps of an HQS frame (hqs, hqs1r, batch-hqs, lod-hqs) a frame records: all of them, or one, for
// frames composited across processes (docs/mpi.md): each draws its depths (Depth), the closest of all is set
// (Renderer::setHqsDepths), each blends its points against it (Blend), the sums of all are set (setHqsSums)
// and one resolves them (Resolve, with the resolve stage of the settings). Other methods record whole frames
// only.
enum class HqsPass { Whole, Depth, Blend, Resolve };

struct RenderSettings {
  Method method; // the first row of the method table: atomicmin
  DepthMode depth = DepthMode::Float;
  // int40: integer steps per unit of linear depth. 0 (default): the 40 bits span [0, distance from the
  // eye to the farthest corner of the scene bounds], e.g. 9 nm per step for a scene 10 km deep.
  double depthScale = 0.0;
  uint32_t background = 0xFF000000u; // RGBA8, opaque black
  uint32_t frames = 1;               // timed frames; the median is reported
  uint32_t warmup = 1;               // untimed frames first (pipeline caches, clocks)
  bool captureWords = false;         // keep canonical words of the last frame for framebufferWords()
  // Batch methods: coordinate words per point, 0 = adaptive (the fewest that keep the decoding error of
  // the batch under half a pixel), 1..3 = forced (3 = full 30-bit precision).
  uint32_t precision = 0;
  bool batchCulling = true; // batch methods: frustum culling of batches (off only to test that it is exact)
  // batch-hqs: dense batches take one pass over their points instead of two (off only to test that the image
  // is the same)
  bool batchHqsDense = true;
  PostSettings post;        // the resolve stage after the method: point size, dilation, eye-dome lighting
  // LOD methods: nodes whose projected size (Potree's: the pixel radius of the node cube's bounding sphere)
  // is under minNodePx are not drawn, nor their subtrees; at most pointBudget points a frame (0: no limit).
  double minNodePx = 100;
  uint64_t pointBudget = 0;
  lod::Foveation foveation; // LOD methods: larger nodes needed away from the image's centre (off by default)
  StereoSettings stereo;    // a stereo Renderer's eyes (render/stereo.h); ignored by a mono one
  // Clip volumes (inside or outside), tested per point by every point method after whole batches and nodes
  // were decided (shared.h, ClipVolumes). The renderer ignores the attribute filters (applied where a cloud
  // is loaded) and ClipMode::Highlight (a tint of the uploaded colors: UploadOptions::filter).
  PointFilter filter;
  HqsPass hqsPass = HqsPass::Whole; // HQS methods: the step(s) each frame records
};
// "adaptive", "1", "2", "3" -> 0..3; throws InputError naming the choices.
uint32_t parsePrecision(std::string_view text);

// Per-frame counts of the batch methods (the 2022 paper's Table 2), of the last timed frame.
struct BatchStats {
  uint64_t batchesProcessed = 0;         // batches of all parts (one workgroup each)
  uint64_t batchesRendered = 0;          // batches not culled
  uint64_t pointsProcessed = 0;          // points of rendered batches
  uint64_t pointsRendered = 0;           // points that passed early-z (did the atomicMin)
  uint64_t pointsBlended = 0;            // batch-hqs: points blended into their pixel's average
  uint64_t pointsByWords[3] = {0, 0, 0}; // points processed with 1, 2, 3 coordinate words
  // batch-hqs: batches drawn in one pass (dense: many points a pixel), their points taken back on pixels
  // where that was wrong, and the dense batches drawn again for those
  uint64_t batchesDense = 0;
  uint64_t pointsTakenBack = 0;
  uint64_t batchesRedrawn = 0;
  // Batches (nodes) culled because the clip volumes keep none of their box's points (RenderSettings::filter);
  // part of batchesProcessed - batchesRendered.
  uint64_t batchesClipped = 0;
  // Bytes of point data read: 4 per coordinate word, 32 per rendered batch's bounds; batch-hqs reads the
  // words twice (depth and accumulation pass) and the color of every blended point, except that a dense
  // batch's words are read once (twice if redrawn) and its colors all in the first pass.
  uint64_t bytesRead = 0;
};

struct FrameStats {
  double medianMs = 0, minMs = 0, maxMs = 0; // GPU time of clear + draw + resolve, timestamp queries
  uint32_t frames = 0;
  std::optional<PostStats> post;   // when the resolve stage ran (its time is part of medianMs too)
  uint64_t points = 0;              // points submitted per frame
  std::optional<BatchStats> batch;  // batch and LOD methods (for LOD, batches are octree nodes)
  std::optional<lod::LodStats> lod; // LOD methods only
};

struct Targets;
struct PostView;
class PointMethod;
class PostStage;
namespace lod {
class LodScene;
class LodPasses;
} // namespace lod

class Renderer {
public:
  // Throws InputError for a zero or oversized image. eyes = 2: a stereo renderer, whose frames draw two
  // images of width x height side by side (the left eye's first unless StereoSettings::crossed), both in one
  // pass with the batch and LOD methods; its image is 2 width x height.
  Renderer(gpu::Context& context, uint32_t width, uint32_t height, uint32_t eyes = 1);
  ~Renderer();

  // Throws UnsupportedError if the device cannot run the method (missing extension or feature) and
  // InputError for a combination that does not exist (hqs with int40 depth, hw-points with the resolve
  // stage), for a scene uploaded in another layout than the method reads (MethodInfo::layout), for more
  // than 64 batched parts, and for resolve-stage settings out of range.
  FrameStats render(std::span<const GpuScene* const> scenes, const Camera& camera,
                    const RenderSettings& settings);
  FrameStats render(const GpuScene& scene, const Camera& camera, const RenderSettings& settings) {
    const GpuScene* one[] = {&scene};
    return render(one, camera, settings);
  }

  // Draws an octree with a LOD method (a row reading SceneLayout::Octree) at full detail: the whole
  // selection for the camera is streamed into the octree's node cache before the timed frames, and drawn in
  // passes when it is larger than the cache (render/lod/lod_render.h). Throws InputError for a method that
  // reads uploaded scenes, and as render() above.
  FrameStats render(lod::LodScene& octree, const Camera& camera, const RenderSettings& settings);
  // One frame of a viewer: the octree selects nodes for the camera, takes what its readers finished and
  // asks them for more; this frame copies the new nodes into the cache and draws the resident part of the
  // selection, never waiting for a reader (render/lod/lod_scene.h). One timed frame (settings.frames and
  // warmup are ignored); FrameStats::lod says whether it changed and whether it converged.
  FrameStats renderFrame(lod::LodScene& octree, const Camera& camera, const RenderSettings& settings);

  // RGBA8 pixels of the last frame, row 0 at the top (width() x height(): both eyes of a stereo frame).
  std::vector<uint32_t> image();
  // Canonical words (depth << 32 | color, all ones where empty) of the last frame rendered with
  // captureWords; for closest-point methods only, or for any method when the resolve stage ran (then the
  // words it ended with, float depth also for int40).
  std::vector<uint64_t> framebufferWords();
  // The same into `into` (width() x height() words): what a process of a distributed job reads every frame
  // to composite. Both read through a read-back buffer the renderer keeps.
  void framebufferWords(std::span<uint64_t> into);
  // The same for the rectangle [x, x + w) x [y, y + h) (inside the image), row by row: what a viewer
  // reads to pick the point under the cursor.
  std::vector<uint64_t> framebufferWords(uint32_t x, uint32_t y, uint32_t w, uint32_t h);
  // Makes a frame composited elsewhere (render/composite.h) this renderer's last frame: `image` (width() x
  // height() pixels) is what image() returns, `words` (one a pixel) what framebufferWords() returns. A
  // viewer whose frames are composited across processes reads them as it reads its own frames' (picking,
  // the overlay's depth test). The octree visibility buffer and the HQS buffers are not the composite's:
  // lodPointAt and hqsDepths refuse after it.
  void showComposite(std::span<const uint32_t> image, std::span<const uint64_t> words);
  // Device address of the RGBA8 image of the last frame (width() x height() words, row 0 at the top), for
  // front ends that show it without a copy to the host. Valid until the Renderer is destroyed.
  uint64_t imageAddress() const;
  // The point a mono frame of `lod` drew in one pass (every viewer frame; render's when the selection fits
  // the node cache) at pixel (x, y), read from its visibility buffer: the node's id in the octree's
  // hierarchy and the point's index among the node's records (NodeSource::readNode's order). nullopt for an
  // empty pixel. Throws InputError, saying why in a few words, after any other frame.
  struct LodPixel {
    uint32_t node = 0;
    uint32_t index = 0;
  };
  std::optional<LodPixel> lodPointAt(uint32_t x, uint32_t y);

  // The buffers between the steps of an HQS frame (HqsPass), after a frame of an HQS method (lod-hqs too):
  // the depth words of the depth pass (depth << 32, all ones where empty), and the blend sums, two words a
  // pixel (r << 32 | g, b << 32 | count) in every method's accumulator layout. Sums of several frames' blends
  // add word by word. Throws InputError when the last frame was not an HQS method's.
  std::vector<uint64_t> hqsDepths();
  void setHqsDepths(std::span<const uint64_t> words);
  std::vector<uint64_t> hqsSums();
  void setHqsSums(std::span<const uint64_t> sums);

  uint32_t width() const; // of the image: eyes() x an eye's width
  uint32_t height() const;
  uint32_t eyes() const;

  // Whether the device can run a method (and why not, in one sentence, when it cannot).
  static bool supports(gpu::Context& context, Method method, std::string* why = nullptr);

private:
  PointMethod& method(const RenderSettings& settings);
  // Validates the resolve stage's settings for the method and makes what it needs; false when off.
  bool preparePost(const RenderSettings& settings);
  void allocateWords();
  std::vector<PostView> postViews(const Camera& camera, const RenderSettings& settings) const;
  // The camera of each half of the image: the given one, or the two eyes in image order.
  std::vector<Camera> views(const Camera& camera, const RenderSettings& settings) const;
  // Fills Targets::scenes' clip volumes for scenes at these origins (one record at least).
  void writeSceneTable(std::span<const glm::dvec3> origins, const RenderSettings& settings);
  FrameStats renderLod(lod::LodScene& octree, const Camera& camera, const RenderSettings& settings,
                       bool resident);
  lod::LodPasses& lodPasses(const RenderSettings& settings);
  gpu::Context& context_;
  std::unique_ptr<Targets> targets_;
  std::map<std::pair<Method, DepthMode>, std::unique_ptr<PointMethod>> methods_;
  std::unique_ptr<PostStage> post_;            // made on the first frame that uses it
  std::unique_ptr<gpu::Buffer> wordsReadback_; // framebufferWords()' read-back buffer, kept
  std::map<Method, std::unique_ptr<lod::LodPasses>> lodPasses_;
  bool wordsCaptured_ = false; // the last frame wrote canonical words
  PointMethod* last_ = nullptr; // the method of the last render() frame
  lod::LodPasses* lodHqs_ = nullptr; // the passes of the last frame when it was lod-hqs's
  // The octree of the last frame when lodPointAt can read it (mono, the lod method, one pass), else null;
  // lodWhy_ says why not.
  lod::LodScene* pickableOctree_ = nullptr;
  std::string lodWhy_ = "the last frame did not draw an octree";
};

} // namespace pointrast
