// A point cloud on the GPU: float32 positions relative to an origin (rounded once from double) and RGBA8
// display colors, split into parts that each fit one buffer. A part is the unit of a dispatch, so scenes
// of billions of points (tens of GB) work on any device whatever its largest buffer or allocation.
//
// The 2022 batch methods read another layout of the same points (SceneLayout::Batched): batches of 10240
// consecutive points, each point's coordinates quantized to 30 bits per axis relative to its batch's
// bounds and split into three words (cloud/batch_words.h), the bounds in a per-batch buffer. Both layouts
// take 16 B a point (the batched one 32 B a batch more) and are built while uploading.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "cloud/cloud.h"
#include "cloud/point_filter.h"
#include "gpu/buffer.h"

namespace pointrast {

namespace gpu {
class Context;
}

// How a scene's points lie in GPU memory; every method reads one of them (MethodInfo::layout).
enum class SceneLayout {
  Float,   // float xyz relative to the origin + RGBA8: the 2019/2021 methods and hw-points
  Batched, // the 2022 batch methods: three words of batch-relative coordinates + RGBA8, bounds per batch
  Octree,  // the LOD methods: no GpuScene, an octree streamed into a node cache (render/lod/lod_scene.h)
};
const char* sceneLayoutName(SceneLayout layout);

struct ScenePart {
  gpu::Buffer positions; // Float: float[3 * count]
  gpu::Buffer colors;    // uint[count]
  // Batched: uint per point (cloud/batch_words.h), padded with zeros to a multiple of 4 points so that
  // batch-prefetch loads whole uvec4s; and shared::BatchBounds per batch.
  gpu::Buffer high, medium, low;
  gpu::Buffer batches;
  uint64_t first = 0; // index of the part's first point in the source cloud
  uint64_t count = 0;
  // Batches of the part (Batched layout): every batch but the part's last holds 10240 points.
  uint64_t batchCount() const;
};

// The buffers of a scene no longer drawn, for the upload that replaces it (GpuScene::takeBuffers(),
// UploadOptions::recycle): a new cloud reuses GPU memory instead of allocating it again.
struct SceneBuffers {
  std::vector<gpu::Buffer> device;  // the parts' buffers, of either layout
  std::vector<gpu::Buffer> staging; // upload staging buffers the scene kept (UploadOptions::keepStaging)
};

struct UploadOptions {
  uint64_t first = 0;          // upload points [first, first + count) of the cloud
  uint64_t count = UINT64_MAX; // clamped to the cloud's size
  // Points per part. 0: as many as fit (Float: largest multiple of 10240 whose positions fit one buffer,
  // <= 64 M; Batched: kMaxPartBatches batches, 67,102,720 points, fewer if the device's buffers are
  // smaller). Batched: at most kMaxPartBatches batches; a batch never straddles two parts, so a multiple of
  // 10240 keeps every batch but the last full. Tests use small parts to exercise the part number of
  // visibility indices.
  uint64_t maxPartPoints = 0;
  SceneLayout layout = SceneLayout::Float;
  bool progress = true;
  // How points become colors (render --color); nullopt: displayColorMode(cloud), decided once per upload.
  std::optional<DisplayColorMode> colors;
  // ClipMode::Highlight: the points inside the clip volumes are tinted (highlightColor) in the uploaded
  // colors, as a color mode is folded in; other modes change nothing here (the renderer clips, per frame).
  std::optional<PointFilter> filter;
  // Buffers of a scene this upload replaces: each buffer the new scene needs takes the smallest of them
  // that holds it and is at most twice its size (so a much smaller cloud does not keep a large cloud's
  // memory); the rest are freed before anything is allocated, so the old and the new scene never hold
  // memory at once. The upload writes every byte the renderer reads, so nothing of the old scene shows.
  // Left empty by the upload.
  SceneBuffers* recycle = nullptr;
  // Keep the staging buffers after the upload (up to 128 MiB of host-visible memory while the scene
  // lives), for an upload that recycles this scene.
  bool keepStaging = false;
};

// The tint of a highlighted point: each channel halfway to the highlight color (255, 200, 0), alpha kept.
uint32_t highlightColor(uint32_t rgba);
// Tints the colors of points [first, first + count) of `cloud` that lie inside the clip volumes of a
// ClipMode::Highlight filter; nothing for any other filter.
void highlightColors(uint32_t* dst, const PointCloud& cloud, uint64_t first, uint64_t count,
                     const PointFilter& filter);

// Points per part of a layout: `requested` (0: as many as fit) bounded by the layout's maximum and by a
// device whose largest buffer holds `bufferLimit` bytes; 0 if not even one batch fits.
uint64_t partCapacity(SceneLayout layout, uint64_t requested, uint64_t bufferLimit);
// GPU bytes of `points` points in a layout (both 16 B a point; Batched adds 32 B a batch of bounds).
uint64_t sceneBytes(SceneLayout layout, uint64_t points);
// Whether `points` points in `layout` fit the device's memory; when not, *why says so in one sentence.
// GpuScene refuses what this refuses; a caller that knows the count early (a file's header, a scene's
// size) asks first, so that nothing is read or generated for a cloud the device cannot hold.
bool sceneFits(const gpu::Context& context, SceneLayout layout, uint64_t points, std::string* why = nullptr);

// An input an upload reads block by block instead of as a PointCloud in memory (arrays a caller holds):
// each block becomes a small cloud of the input's scale and offset, whose batches encode exactly as the
// same points of the whole cloud would, so nothing the size of the input is made on the host.
class PointBlocks {
public:
  virtual ~PointBlocks() = default;
  // The input without its points (size 0): its scale, offset, bounds and source.
  virtual const PointCloud& shape() const = 0;
  virtual uint64_t size() const = 0;
  // Points [first, first + count) into `out`, made with shape()'s scale and offset: positions, and colors
  // where the input has them. Called from several threads at once, each with its own `out`.
  virtual void fill(uint64_t first, uint64_t count, PointCloud& out) const = 0;
};

// Seconds an upload spent: encoding on the host (its threads' wall time, chunk by chunk) and waiting for
// copies to the GPU that the encoding did not hide.
struct UploadTimes {
  double total = 0, encode = 0, copyWait = 0;
  double allocate = 0; // the device buffers and the staging buffers (~0 where recycled ones sufficed)
  uint64_t reusedBytes = 0, allocatedBytes = 0; // of those buffers, taken from a recycled scene / new
  // The encoding's steps, in seconds of all its threads together (a batched upload): reading the points
  // (positions and colors from the input), cutting batches (their bounds), the position words, the
  // display colors, and copying each thread's words into the staging buffer.
  double readCpu = 0, boundsCpu = 0, wordsCpu = 0, colorsCpu = 0, stageCpu = 0;
  uint32_t threads = 0;
};

class GpuScene {
public:
  // Uploads through a staging buffer; positions are relative to cloud.origin() whatever the subrange,
  // so scenes uploaded from parts of one cloud draw exactly the points the whole upload would. Batched:
  // batches are cut from the first uploaded point on. Throws UnsupportedError when the device lacks the
  // memory.
  GpuScene(gpu::Context& context, const PointCloud& cloud, const UploadOptions& options = {});
  // The same upload from blocks (the Batched layout only: UnsupportedError for another). The colors come
  // from UploadOptions::colors, which must be given (the whole input is never looked at to choose them).
  GpuScene(gpu::Context& context, const PointBlocks& blocks, const UploadOptions& options);

  uint64_t pointCount() const { return pointCount_; }
  const glm::dvec3& origin() const { return origin_; }
  const Bounds& bounds() const { return bounds_; }
  const std::vector<ScenePart>& parts() const { return parts_; }
  SceneLayout layout() const { return layout_; }
  // Bytes of point data in GPU memory (sceneBytes()).
  uint64_t bytes() const { return sceneBytes(layout_, pointCount_); }
  const UploadTimes& uploadTimes() const { return times_; }

  // Rewrites the colors of every part from `cloud` (the one uploaded, same subrange) in another mode:
  // 4 B a point instead of a whole upload, so a viewer switches modes without uploading positions again.
  // `filter`: a ClipMode::Highlight filter tints as at upload (UploadOptions::filter).
  void recolor(gpu::Context& context, const PointCloud& cloud, const DisplayColorMode& mode,
               const std::optional<PointFilter>& filter = std::nullopt);

  // Gives up the scene's buffers for an upload that replaces it (UploadOptions::recycle). The scene is
  // left empty: no points, no parts; it draws nothing.
  SceneBuffers takeBuffers();

private:
  void uploadFloat(gpu::Context& context, const PointCloud& cloud, const DisplayColorMode& colors,
                   bool progress);
  // The points [first, first + count) of the input as a cloud and the index of the first of them in it:
  // the input cloud itself, or `scratch` filled from blocks.
  using PointsView = std::function<std::pair<const PointCloud*, uint64_t>(uint64_t first, uint64_t count,
                                                                          PointCloud& scratch)>;
  void makeParts(gpu::Context& context, uint64_t first, uint64_t count, const UploadOptions& options);
  // A staging buffer of at least `bytes`: a kept one (staging_) or a new one; given back with
  // endStaging(), which keeps it where UploadOptions::keepStaging asked.
  gpu::Buffer takeStaging(gpu::Context& context, uint64_t bytes, const std::string& name);
  void endStaging(std::vector<gpu::Buffer> used);
  void uploadBatched(gpu::Context& context, const PointsView& points, const DisplayColorMode& colors,
                     bool progress);
  std::optional<PointFilter> highlight_; // the filter whose inside points are tinted, if any
  std::vector<gpu::Buffer> staging_;     // staging buffers kept for a later upload (keepStaging)
  bool keepStaging_ = false;
  std::vector<ScenePart> parts_;
  SceneLayout layout_ = SceneLayout::Float;
  uint64_t pointCount_ = 0;
  glm::dvec3 origin_{0};
  Bounds bounds_;
  UploadTimes times_;
};

} // namespace pointrast
