#include "render/scene.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "base/error.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "cloud/batch_words.h"
#include "gpu/context.h"
#include "gpu/shared_types.h"

namespace pointrast {

namespace {

constexpr uint64_t kStagingBytes = 64ull << 20; // per copy: 64 MiB, 4 M points of 16 B
constexpr uint64_t kStagingPoints = kStagingBytes / 16;
constexpr uint64_t kPartAlign = 10240;           // parts hold whole 2022-style batches
constexpr uint64_t kMaxPartPoints = 64ull << 20; // 64 M points: 768 MiB of positions

// Batched upload: whole batches per staging copy, 16 B a point plus their bounds: 409 batches, 4.2 M points.
constexpr uint64_t kBatchBytes = kBatchSize * 16 + sizeof(shared::BatchBounds);
constexpr uint64_t kStagingBatches = kStagingBytes / kBatchBytes;
constexpr uint64_t kStagingBatchPoints = kStagingBatches * kBatchSize;
static_assert(kBatchSize == shared::kBatchPoints);

uint64_t roundUp4(uint64_t n) {
  return (n + 3) & ~uint64_t(3);
}

static_assert(kStagingBatches * kBatchBytes <= kStagingBytes);

// The smallest buffer of `pool` that holds `bytes` and is at most twice as large, moved out of it; an
// empty buffer when none is.
gpu::Buffer takeFitting(std::vector<gpu::Buffer>& pool, uint64_t bytes) {
  auto best = pool.end();
  for (auto it = pool.begin(); it != pool.end(); ++it)
    if (it->size() >= bytes && it->size() / 2 <= bytes && (best == pool.end() || it->size() < best->size()))
      best = it;
  if (best == pool.end()) return {};
  gpu::Buffer taken = std::move(*best);
  *best = std::move(pool.back());
  pool.pop_back();
  return taken;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace

const char* sceneLayoutName(SceneLayout layout) {
  return layout == SceneLayout::Batched ? "batched" : layout == SceneLayout::Octree ? "octree" : "float";
}

uint64_t ScenePart::batchCount() const {
  return (count + kBatchSize - 1) / kBatchSize;
}

uint64_t partCapacity(SceneLayout layout, uint64_t requested, uint64_t bufferLimit) {
  if (layout == SceneLayout::Float) {
    if (requested) return requested;
    return std::min(kMaxPartPoints, (bufferLimit / 12) / kPartAlign * kPartAlign);
  }
  // The largest buffer of a batched part is one word (or one color) per point. (A requested size that is
  // no multiple of 10240 works too: each part's last batch is short.)
  uint64_t fit = std::min<uint64_t>(shared::kMaxPartBatches, (bufferLimit / 4) / kBatchSize) * kBatchSize;
  return requested ? std::min(requested, fit) : fit;
}

uint64_t sceneBytes(SceneLayout layout, uint64_t points) {
  uint64_t bytes = points * 16;
  if (layout == SceneLayout::Batched)
    bytes += (points + kBatchSize - 1) / kBatchSize * sizeof(shared::BatchBounds);
  return bytes;
}

bool sceneFits(const gpu::Context& context, SceneLayout layout, uint64_t points, std::string* why) {
  const uint64_t have = context.deviceLocalBytes();
  // The first test keeps a hostile count from wrapping sceneBytes() around to a size that fits.
  if (points <= have / 16 && sceneBytes(layout, points) <= have) return true;
  if (why)
    *why = std::to_string(points) + " points need " +
           std::to_string(uint64_t(double(points) * 16 / 1048576)) + " MiB of GPU memory (the " +
           sceneLayoutName(layout) + " layout, 16 B a point) but device '" + context.info().name + "' has " +
           std::to_string(have >> 20) + " MiB";
  return false;
}

GpuScene::GpuScene(gpu::Context& context, const PointCloud& cloud, const UploadOptions& options)
    : layout_(options.layout), origin_(cloud.origin()), bounds_(cloud.bounds) {
  const auto start = std::chrono::steady_clock::now();
  uint64_t first = std::min(options.first, cloud.size());
  uint64_t count = std::min(options.count, cloud.size() - first);
  makeParts(context, first, count, options);
  if (count == 0) {
    endStaging({});
    return;
  }
  const DisplayColorMode colors = options.colors ? *options.colors : displayColorMode(cloud); // once
  if (options.filter && options.filter->hasClip() && options.filter->clipMode == ClipMode::Highlight)
    highlight_ = options.filter;
  if (layout_ == SceneLayout::Float)
    uploadFloat(context, cloud, colors, options.progress);
  else
    uploadBatched(
        context,
        [&](uint64_t at, uint64_t, PointCloud&) {
          return std::pair{&cloud, at};
        },
        colors, options.progress);
  times_.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

GpuScene::GpuScene(gpu::Context& context, const PointBlocks& blocks, const UploadOptions& options)
    : layout_(options.layout), origin_(blocks.shape().origin()), bounds_(blocks.shape().bounds) {
  const auto start = std::chrono::steady_clock::now();
  if (layout_ != SceneLayout::Batched)
    throw UnsupportedError(std::string("an upload from blocks makes the batched layout, not ") +
                           sceneLayoutName(layout_));
  if (!options.colors) throw InternalError("an upload from blocks needs its color mode");
  const uint64_t first = std::min(options.first, blocks.size());
  const uint64_t count = std::min(options.count, blocks.size() - first);
  makeParts(context, first, count, options);
  if (count == 0) {
    endStaging({});
    return;
  }
  if (options.filter && options.filter->hasClip() && options.filter->clipMode == ClipMode::Highlight)
    highlight_ = options.filter;
  const PointCloud& shape = blocks.shape();
  uploadBatched(
      context,
      [&](uint64_t at, uint64_t n, PointCloud& scratch) {
        scratch.scale = shape.scale;
        scratch.offset = shape.offset;
        scratch.bounds = shape.bounds;
        scratch.source = shape.source;
        blocks.fill(at, n, scratch);
        return std::pair<const PointCloud*, uint64_t>{&scratch, 0};
      },
      *options.colors, options.progress);
  times_.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void GpuScene::makeParts(gpu::Context& context, uint64_t first, uint64_t count,
                         const UploadOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  struct Timed {
    double& seconds;
    std::chrono::steady_clock::time_point start;
    ~Timed() { seconds += secondsSince(start); }
  } timed{times_.allocate, start};
  // Buffers of a replaced scene: the device ones are matched below, the rest freed on return.
  std::vector<gpu::Buffer> spare;
  keepStaging_ = options.keepStaging;
  if (options.recycle) {
    spare = std::move(options.recycle->device);
    options.recycle->device.clear();
    staging_ = std::move(options.recycle->staging);
    options.recycle->staging.clear();
  }
  pointCount_ = count;
  uint64_t limit = std::min(context.maxAllocationSize(), context.maxBufferSize());
  uint64_t partPoints = partCapacity(layout_, options.maxPartPoints, limit);
  if (partPoints == 0)
    throw UnsupportedError("device buffers are too small to hold even one batch of points");

  std::string why;
  if (!sceneFits(context, layout_, count, &why)) throw UnsupportedError("the cloud does not fit: " + why);

  for (uint64_t at = 0; at < count; at += partPoints) {
    ScenePart part;
    part.first = first + at;
    part.count = std::min(partPoints, count - at);
    parts_.push_back(std::move(part));
  }
  struct Need {
    gpu::Buffer* buffer;
    uint64_t bytes;
    std::string name;
  };
  std::vector<Need> needs;
  for (size_t i = 0; i < parts_.size(); ++i) {
    ScenePart& part = parts_[i];
    const std::string index = " " + std::to_string(i);
    if (layout_ == SceneLayout::Float) {
      needs.push_back({&part.positions, part.count * 12, "positions" + index});
    } else {
      needs.push_back({&part.high, roundUp4(part.count) * 4, "high words" + index});
      needs.push_back({&part.medium, roundUp4(part.count) * 4, "medium words" + index});
      needs.push_back({&part.low, roundUp4(part.count) * 4, "low words" + index});
      needs.push_back(
          {&part.batches, part.batchCount() * sizeof(shared::BatchBounds), "batch bounds" + index});
    }
    needs.push_back({&part.colors, part.count * 4, "colors" + index});
  }
  // The largest first, so that a small buffer does not take the spare one a larger buffer needed.
  std::stable_sort(needs.begin(), needs.end(),
                   [](const Need& a, const Need& b) { return a.bytes > b.bytes; });
  for (Need& need : needs) {
    *need.buffer = takeFitting(spare, need.bytes);
    if (!*need.buffer) continue;
    times_.reusedBytes += need.buffer->size();
    context.setName(VK_OBJECT_TYPE_BUFFER, uint64_t(need.buffer->handle()), need.name);
  }
  spare.clear(); // freed before the new buffers are allocated
  for (Need& need : needs) {
    if (*need.buffer) continue;
    *need.buffer = gpu::Buffer(context, need.bytes, gpu::kBufferUsage, gpu::MemoryKind::Device, need.name);
    times_.allocatedBytes += need.bytes;
  }
}

gpu::Buffer GpuScene::takeStaging(gpu::Context& context, uint64_t bytes, const std::string& name) {
  const auto start = std::chrono::steady_clock::now();
  auto it =
      std::find_if(staging_.begin(), staging_.end(), [&](const gpu::Buffer& b) { return b.size() >= bytes; });
  gpu::Buffer buffer;
  if (it != staging_.end()) {
    buffer = std::move(*it);
    staging_.erase(it);
    times_.reusedBytes += buffer.size();
  } else {
    buffer = gpu::Buffer(context, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryKind::Upload, name);
    times_.allocatedBytes += bytes;
  }
  times_.allocate += secondsSince(start);
  return buffer;
}

void GpuScene::endStaging(std::vector<gpu::Buffer> used) {
  if (!keepStaging_) {
    staging_.clear();
    return;
  }
  for (gpu::Buffer& buffer : used)
    staging_.push_back(std::move(buffer));
}

SceneBuffers GpuScene::takeBuffers() {
  SceneBuffers out;
  for (ScenePart& part : parts_)
    for (gpu::Buffer* buffer :
         {&part.positions, &part.colors, &part.high, &part.medium, &part.low, &part.batches})
      if (*buffer) out.device.push_back(std::move(*buffer));
  out.staging = std::move(staging_);
  staging_.clear();
  parts_.clear();
  pointCount_ = 0;
  return out;
}

void GpuScene::uploadFloat(gpu::Context& context, const PointCloud& cloud, const DisplayColorMode& colors,
                           bool progressShown) {
  gpu::Buffer staging = takeStaging(context, kStagingBytes, "upload staging");
  auto* stagingFloats = static_cast<float*>(staging.mapped());
  auto* stagingColors =
      reinterpret_cast<uint32_t*>(static_cast<char*>(staging.mapped()) + kStagingPoints * 12);
  Progress progress("uploading to GPU", pointCount_, " points", progressShown);
  for (const ScenePart& part : parts_) {
    for (uint64_t at = 0; at < part.count; at += kStagingPoints) {
      uint64_t n = std::min(kStagingPoints, part.count - at);
      toRelativeFloat(stagingFloats, cloud, part.first + at, n, origin_);
      displayColors(stagingColors, cloud, part.first + at, n, colors);
      if (highlight_) highlightColors(stagingColors, cloud, part.first + at, n, *highlight_);
      context.submitAndWait([&](VkCommandBuffer cmd) {
        VkBufferCopy pos{0, at * 12, n * 12};
        VkBufferCopy col{kStagingPoints * 12, at * 4, n * 4};
        gpu::vkCmdCopyBuffer(cmd, staging.handle(), part.positions.handle(), 1, &pos);
        gpu::vkCmdCopyBuffer(cmd, staging.handle(), part.colors.handle(), 1, &col);
      });
      progress.advance(n);
    }
  }
  std::vector<gpu::Buffer> used;
  used.push_back(std::move(staging));
  endStaging(std::move(used));
}

// Encodes whole batches on all cores (bounds, three words, colors per batch, as cloud/batch_words.h
// defines them), each group of batches first into memory of its thread and then copied into a staging
// buffer in four long runs (staging memory may be uncached, write-combined: scattered small writes to it
// are slow), then copies the staging buffer into the part's buffers. Two staging buffers take turns:
// while the GPU copies one chunk, a second thread encodes the next into the other, so the copies cost no
// time beside the encoding.
void GpuScene::uploadBatched(gpu::Context& context, const PointsView& points,
                             const DisplayColorMode& colorMode, bool progressShown) {
  struct Chunk {
    const ScenePart* part;
    uint64_t at, n; // points [at, at + n) of the part
  };
  std::vector<Chunk> chunks;
  for (const ScenePart& part : parts_)
    for (uint64_t at = 0; at < part.count; at += kStagingBatchPoints)
      chunks.push_back({&part, at, std::min(kStagingBatchPoints, part.count - at)});
  if (chunks.empty()) return;
  std::atomic<int64_t> stepNs[5] = {}; // the encoding's steps, as UploadTimes counts them
  // Whole staging buffers (64 MiB, as the float upload's), so that either upload can reuse the other's.
  gpu::Buffer staging[2] = {takeStaging(context, kStagingBytes, "upload staging 0"),
                            takeStaging(context, chunks.size() > 1 ? kStagingBytes : 16, "upload staging 1")};
  // Staging sections: high, medium, low words, colors (kStagingBatchPoints each), then the bounds.
  auto section = [&](int s, int k) {
    return static_cast<uint32_t*>(staging[s].mapped()) + k * kStagingBatchPoints;
  };
  // Batches a thread encodes before it copies them to the staging buffer: 2 make about 200 jobs of a
  // chunk, which keep 16 threads evenly busy to its end.
  constexpr uint64_t kGroup = 2;
  auto encode = [&](int s, const Chunk& c) {
    const auto start = std::chrono::steady_clock::now();
    uint32_t* words[4] = {section(s, 0), section(s, 1), section(s, 2), section(s, 3)};
    auto* bounds = reinterpret_cast<shared::BatchBounds*>(section(s, 4));
    const uint64_t batches = (c.n + kBatchSize - 1) / kBatchSize;
    parallelBlocks(batches, kGroup, [&](uint64_t, uint64_t begin, uint64_t end) {
      // Memory of this thread kept from job to job (a 1 G-point upload has some 50,000 jobs): fresh
      // allocations were new pages to fault in and clear each time. The scratch cloud takes the kept
      // positions (every value written by the fill) and colors (emptied: a fill without colors leaves none).
      thread_local std::vector<uint32_t> local;
      thread_local std::vector<int32_t> keptPositions;
      thread_local std::vector<uint32_t> keptColors;
      local.resize(4 * kGroup * kBatchSize); // every word written
      uint32_t* mine[4];
      for (int k = 0; k < 4; ++k)
        mine[k] = local.data() + k * kGroup * kBatchSize;
      PointCloud scratch;
      scratch.positions.swap(keptPositions);
      scratch.colors.swap(keptColors);
      scratch.colors.clear();
      // Nanoseconds of each step in this job (a clock read per step of a batch: ~10,000 points each).
      int64_t ns[5] = {};
      auto clock = [] { return std::chrono::steady_clock::now(); };
      auto lap = [&](std::chrono::steady_clock::time_point& t, int step) {
        const auto now = clock();
        ns[step] += std::chrono::duration_cast<std::chrono::nanoseconds>(now - t).count();
        t = now;
      };
      const uint64_t from = begin * kBatchSize, to = std::min(c.n, end * kBatchSize);
      for (uint64_t b = begin; b < end; ++b) {
        const uint64_t at = b * kBatchSize; // in this chunk
        const uint32_t n = uint32_t(std::min(kBatchSize, c.n - at));
        auto t = clock();
        const auto [cloud, index] = points(c.part->first + c.at + at, n, scratch);
        lap(t, 0);
        const Batch batch = makeBatch(*cloud, index, n);
        lap(t, 1);
        const uint64_t k = at - from;
        encodeBatchWords(mine[0] + k, mine[1] + k, mine[2] + k, *cloud, batch);
        lap(t, 2);
        displayColors(mine[3] + k, *cloud, batch.first, batch.count, colorMode);
        if (highlight_) highlightColors(mine[3] + k, *cloud, batch.first, batch.count, *highlight_);
        lap(t, 3);
        const glm::dvec3 lo = batch.bounds.min - origin_, hi = batch.bounds.max - origin_;
        bounds[b] = {glm::vec4(glm::vec3(lo), 0.0f), glm::vec4(glm::vec3(hi), 0.0f)};
      }
      auto t = clock();
      for (int k = 0; k < 4; ++k)
        std::memcpy(words[k] + from, mine[k], (to - from) * 4);
      lap(t, 4);
      for (int step = 0; step < 5; ++step)
        stepNs[step].fetch_add(ns[step], std::memory_order_relaxed);
      keptPositions.swap(scratch.positions);
      keptColors.swap(scratch.colors);
    });
    // Zero the padding words of a part's last, partial group of four (batch-prefetch loads them).
    for (uint64_t k = c.n; k < roundUp4(c.n); ++k)
      words[0][k] = words[1][k] = words[2][k] = 0;
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  auto copy = [&](int s, const Chunk& c) {
    const ScenePart& part = *c.part;
    const uint64_t wordBytes = roundUp4(c.n) * 4, batches = (c.n + kBatchSize - 1) / kBatchSize;
    const VkBuffer from = staging[s].handle();
    context.submitAndWait([&](VkCommandBuffer cmd) {
      const gpu::Buffer* targets[3] = {&part.high, &part.medium, &part.low};
      for (int w = 0; w < 3; ++w) {
        VkBufferCopy words{w * kStagingBatchPoints * 4, c.at * 4, wordBytes};
        gpu::vkCmdCopyBuffer(cmd, from, targets[w]->handle(), 1, &words);
      }
      VkBufferCopy col{3 * kStagingBatchPoints * 4, c.at * 4, c.n * 4};
      gpu::vkCmdCopyBuffer(cmd, from, part.colors.handle(), 1, &col);
      VkBufferCopy box{4 * kStagingBatchPoints * 4, c.at / kBatchSize * sizeof(shared::BatchBounds),
                       batches * sizeof(shared::BatchBounds)};
      gpu::vkCmdCopyBuffer(cmd, from, part.batches.handle(), 1, &box);
    });
  };
  Progress progress("uploading to GPU (batched)", pointCount_, " points", progressShown);
  times_.threads = hardwareThreads();
  times_.encode += encode(0, chunks[0]);
  for (size_t i = 0; i < chunks.size(); ++i) {
    std::exception_ptr failed;
    std::thread next;
    double encoded = 0;
    if (i + 1 < chunks.size())
      next = std::thread([&, i] {
        try {
          encoded = encode(int((i + 1) % 2), chunks[i + 1]);
        } catch (...) {
          failed = std::current_exception();
        }
      });
    const auto copyStart = std::chrono::steady_clock::now();
    try {
      copy(int(i % 2), chunks[i]);
    } catch (...) {
      if (next.joinable()) next.join();
      throw;
    }
    const double copied = std::chrono::duration<double>(std::chrono::steady_clock::now() - copyStart).count();
    if (next.joinable()) next.join();
    if (failed) std::rethrow_exception(failed);
    times_.encode += encoded;
    times_.copyWait += std::max(0.0, copied - encoded); // the copy's time the encoding did not cover
    progress.advance(chunks[i].n);
  }
  double* cpu[5] = {&times_.readCpu, &times_.boundsCpu, &times_.wordsCpu, &times_.colorsCpu,
                    &times_.stageCpu};
  for (int step = 0; step < 5; ++step)
    *cpu[step] += double(stepNs[step].load()) * 1e-9;
  std::vector<gpu::Buffer> used;
  for (gpu::Buffer& buffer : staging)
    used.push_back(std::move(buffer));
  endStaging(std::move(used));
}

uint32_t highlightColor(uint32_t rgba) {
  constexpr uint32_t kTint[3] = {255, 200, 0};
  uint32_t out = rgba & 0xFF000000u;
  for (int c = 0; c < 3; ++c)
    out |= (((rgba >> (8 * c)) & 0xFFu) + kTint[c] + 1) / 2 << (8 * c);
  return out;
}

void highlightColors(uint32_t* dst, const PointCloud& cloud, uint64_t first, uint64_t count,
                     const PointFilter& filter) {
  if (!filter.hasClip() || filter.clipMode != ClipMode::Highlight) return;
  for (uint64_t i = 0; i < count; ++i)
    if (insideClip(filter, cloud.world(first + i))) dst[i] = highlightColor(dst[i]);
}

// Colors of a part are the same in both layouts: one uint per point, in point order.
void GpuScene::recolor(gpu::Context& context, const PointCloud& cloud, const DisplayColorMode& mode,
                       const std::optional<PointFilter>& filter) {
  highlight_.reset();
  if (filter && filter->hasClip() && filter->clipMode == ClipMode::Highlight) highlight_ = filter;
  assert(parts_.empty() || parts_.back().first + parts_.back().count <= cloud.size());
  gpu::Buffer staging(context, kStagingBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryKind::Upload,
                      "recolor staging");
  auto* colors = static_cast<uint32_t*>(staging.mapped());
  constexpr uint64_t kChunk = kStagingBytes / 4;
  for (const ScenePart& part : parts_) {
    for (uint64_t at = 0; at < part.count; at += kChunk) {
      const uint64_t n = std::min(kChunk, part.count - at);
      displayColors(colors, cloud, part.first + at, n, mode);
      if (highlight_) highlightColors(colors, cloud, part.first + at, n, *highlight_);
      context.submitAndWait([&](VkCommandBuffer cmd) {
        VkBufferCopy copy{0, at * 4, n * 4};
        gpu::vkCmdCopyBuffer(cmd, staging.handle(), part.colors.handle(), 1, &copy);
      });
    }
  }
}

} // namespace pointrast
