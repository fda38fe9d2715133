// sphere-compute: spheres rasterized in compute shaders into the visibility buffer of the 2022 point
// renderer (Schuetz et al., "Software Rasterization of 2 Billion Points in Real Time"): per pixel the 64-bit
// minimum of floatBits(view depth of the ray hit) << 32 | particle index, then a resolve that shades the
// winner. Five passes per frame (shaders/sphere_*.comp.glsl):
//   1. one thread per sphere: cull, then ray-test the pixel box alone if it has at most 64 pixels, or
//      append its chunks to the large-sphere list: 16 x 16 screen tiles clipped to the box if the box is
//      much larger than a tile, else bands of whole box rows (up to 256 pixels each). With occlusion
//      culling (the default) this pass runs twice, on batches of 128 consecutive particles whose bounds are
//      computed once per particle set (sphere_batch_bounds.comp): first on the batches visible in the last
//      frame, then, after a depth pyramid of what they drew (sphere_hiz.comp) and a test of every batch's
//      bounds against it (sphere_batch_cull.comp), on the batches that may show and were not drawn yet.
//      A hidden batch costs a read of its bounds instead of its particles: most of a dense set seen from
//      outside;
//   2. one thread per listed chunk: a chunk whose sphere surely covers its whole tile lowers the tile's
//      depth bound;
//   3. one thread per listed chunk: a chunk behind the bounds of the tiles it touches is dropped (the
//      overdraw of close-ups, where most large spheres are hidden), the others are listed to draw;
//   4. the chunks left to draw, one per workgroup iteration, one pixel per thread;
//   5. resolve: shade the winning sphere at each pixel.
#include <algorithm>
#include <map>

#include "base/error.h"
#include "base/parallel.h"
#include "gpu/context.h"
#include "gpu/program.h"
#include "gpu/timer.h"
#include "render/spheres/sphere_method.h"
#include "render/spheres/sphere_visibility.h"

namespace pointrast {

namespace {

// Default capacity of the large-sphere list: 8 M chunks of up to 16 x 16 pixels (128 MiB of entries). An
// eye inside 10 M uniform particles overflowed 1 M chunks of 256 box pixels (H200: 108 ms, 40 % of the
// spheres drawing chunks themselves; hardware depth testing needs 12 ms there), and tiles list up to ~2x
// as many chunks as runs of 256 box pixels did (a box straddles tile borders): the riemann-like stand-in's
// first short-orbit camera lists 3.1 M at 1920x1080, where runs listed at most 1.5 M.
constexpr uint32_t kDefaultChunkCapacity = 8u << 20;
// Chunks one invocation of the large pass may loop over on a CPU device (llvmpipe: 65535 loop iterations
// per invocation, all loops together; the rest for the loops inside one chunk's work).
constexpr uint32_t kCpuLoopIterations = 32768;
constexpr uint64_t kChunkHeaderBytes = 16; // 64-bit count, spilled, drawn (entries are 16-byte aligned)
constexpr uint64_t kCounterBytes = 16;     // SphereFrame::counters, uint[4]
constexpr uint64_t kBatchListHeaderBytes = 16; // SphereBatchList: count, 3 reserved
// Listed batches one invocation of a list draw may loop over on a CPU device (see kCpuLoopIterations).
constexpr uint64_t kCpuListBatches = 64;

struct Programs {
  gpu::ComputeProgram raster, bound, cull, large, resolve;
  // Occlusion culling: the per-sphere pass over a list of batches, the pyramid and the batch test.
  gpu::ComputeProgram rasterList, hiz, batchCull;
};

// The pipelines' variant: the particle layout and the switches of sphere_raster.inc.glsl.
struct Variant {
  uint32_t layout;
  bool countWork, tileBound;
  uint32_t tileCutPixels;
  bool occlusionCull;
  auto operator<=>(const Variant&) const = default;
};

class SphereComputeMethod : public SphereMethodImpl {
public:
  SphereComputeMethod(gpu::Context& context, uint32_t width, uint32_t height)
      : context_(context), pixels_(uint64_t(width) * height) {
    framebuffer_ = gpu::Buffer(context, pixels_ * 8, gpu::kBufferUsage, gpu::MemoryKind::Device,
                               "sphere visibility buffer");
    chunks_ = gpu::Buffer(context, kChunkHeaderBytes + uint64_t(kDefaultChunkCapacity) * 16,
                          gpu::kBufferUsage, gpu::MemoryKind::Device, "large-sphere chunks");
    drawnChunks_ = gpu::Buffer(context, uint64_t(kDefaultChunkCapacity) * 4, gpu::kBufferUsage,
                               gpu::MemoryKind::Device, "large-sphere chunks to draw");
    tilesX_ = (width + shared::kSphereTileSide - 1) / shared::kSphereTileSide;
    tiles_ = uint64_t(tilesX_) * ((height + shared::kSphereTileSide - 1) / shared::kSphereTileSide);
    tileBounds_ = gpu::Buffer(context, tiles_ * 4, gpu::kBufferUsage, gpu::MemoryKind::Device,
                              "sphere tile depth bounds");
    counters_ = gpu::Buffer(context, kCounterBytes, gpu::kBufferUsage, gpu::MemoryKind::Device,
                            "sphere-compute work counters");
    tilesY_ = (height + shared::kSphereTileSide - 1) / shared::kSphereTileSide;
    coarseX_ = (tilesX_ + shared::kSphereCoarseTiles - 1) / shared::kSphereCoarseTiles;
    coarse_ = uint64_t(coarseX_) * ((tilesY_ + shared::kSphereCoarseTiles - 1) / shared::kSphereCoarseTiles);
    hiz_ = gpu::Buffer(context, (tiles_ * (1 + shared::kSphereFinePerTile * shared::kSphereFinePerTile) + coarse_) * 4,
                       gpu::kBufferUsage, gpu::MemoryKind::Device, "sphere depth pyramid");
    // The large pass strides over the list with a fixed grid: enough workgroups to fill a big GPU
    // (4096 x 256 threads), or a few per core on a CPU device, where idle workgroups are not free, but
    // at least enough that no invocation loops over more than kCpuLoopIterations chunks: llvmpipe ends
    // every loop of an invocation after 65535 iterations in all (its loop limiter), which silently left
    // the chunks past 8 x 65535 undrawn on a 2-core machine.
    largeGroups_ = context.info().software()
                       ? std::max(4 * hardwareThreads(), unsigned(kDefaultChunkCapacity / kCpuLoopIterations))
                       : 4096;
  }

  void prepare(const SphereSettings& settings, shared::SphereFrame& frame) override {
    frame.framebuffer = framebuffer_.address();
    frame.chunks = chunks_.address();
    chunkCapacity_ = settings.chunkCapacity ? std::min(settings.chunkCapacity, kDefaultChunkCapacity)
                                            : kDefaultChunkCapacity;
    frame.chunkCapacity = chunkCapacity_;
    frame.drawnChunks = drawnChunks_.address();
    frame.tilesX = tilesX_;
    frame.tileBounds = tileBounds_.address();
    frame.counters = counters_.address();
    variant_ = {0, settings.countWork, settings.tileBound,
                settings.tileCutPixels ? settings.tileCutPixels : shared::kSphereTileCutPixels,
                settings.occlusionCull};
    frame.hiz = hiz_.address();
    frame.coarseX = coarseX_;
    frame.coarseOffset = uint32_t(tiles_);
    frame.fineOffset = uint32_t(tiles_ + coarse_);
  }

  // Occlusion culling: the batches' bounds and flags, rebuilt when the particle set changes (a set is
  // drawn by many frames; its bounds cost one read of every particle).
  double build(const GpuParticles& particles, SphereTargets& targets) override {
    if (!variant_.occlusionCull || particles.count() == 0) return 0;
    uint64_t perPart = (particles.partCapacity() + shared::kSphereBatchSize - 1) / shared::kSphereBatchSize;
    // Every part but the last is full; the last part's slots end with its particles.
    uint64_t batches = perPart * (particles.parts().size() - 1) +
                       (particles.parts().back().count + shared::kSphereBatchSize - 1) / shared::kSphereBatchSize;
    if (batches > 0xFFFFFFFFull) throw UnsupportedError("sphere-compute: too many particle batches");
    auto* frame = static_cast<shared::SphereFrame*>(targets.frameStaging.mapped());
    if (particles.id() != particlesId_) {
      particlesId_ = 0;
      batchBounds_ = gpu::Buffer(context_, batches * 32, gpu::kBufferUsage, gpu::MemoryKind::Device,
                                 "sphere batch bounds");
      batchFlags_ = gpu::Buffer(context_, batches * 4, gpu::kBufferUsage, gpu::MemoryKind::Device,
                                "sphere batch flags");
      batchList_ = gpu::Buffer(context_, kBatchListHeaderBytes + batches * 4, gpu::kBufferUsage,
                               gpu::MemoryKind::Device, "sphere batches to draw late");
      for (gpu::Buffer& list : visibleLists_)
        list = gpu::Buffer(context_, kBatchListHeaderBytes + batches * 4, gpu::kBufferUsage,
                           gpu::MemoryKind::Device, "sphere batches visible");
      batches_ = uint32_t(batches);
    }
    frame->batchBounds = batchBounds_.address();
    frame->batchFlags = batchFlags_.address();
    frame->batchList = batchList_.address();
    frame->batches = batches_;
    frame->batchesPerPart = uint32_t(perPart);
    if (particles.id() == particlesId_) return 0;
    // One batch per thread.
    gpu::ComputeProgram boundsProgram(context_, "sphere_batch_bounds.comp",
                                      {{/* LAYOUT= */ 0, particleLayoutInfo(particles.layout()).shaderId}});
    gpu::Grid grid = gpu::gridFor(batches_, boundsProgram.groupSize());
    shared::SpherePush push{};
    push.frame = targets.frameStaging.address();
    push.particles = visibleLists_[current_].address();
    push.groupsX = grid.x;
    gpu::TimestampPool timer(context_, 1);
    context_.submitAndWait([&](VkCommandBuffer cmd) {
      timer.reset(cmd);
      timer.begin(cmd, 0);
      gpu::vkCmdFillBuffer(cmd, visibleLists_[current_].handle(), 0, 4, batches_); // every batch listed
      gpu::fullBarrier(cmd);
      boundsProgram.dispatch(cmd, grid.x, grid.y, push);
      timer.end(cmd, 0);
    });
    particlesId_ = particles.id();
    // The draws of listed batches stride over their list with a fixed grid: enough workgroups to fill a
    // big GPU, or on a CPU device a few per core but at least one per kCpuListBatches batches (llvmpipe's
    // loop limit counts every iteration of an invocation: the batches it strides over and the pixels and
    // chunks of each of their spheres; see largeGroups_).
    uint64_t groups = context_.info().software()
                          ? std::max<uint64_t>(4 * hardwareThreads(), (batches_ + kCpuListBatches - 1) / kCpuListBatches)
                          : 4096;
    listGroups_ = uint32_t(std::min<uint64_t>({groups, batches_, 65535}));
    return timer.milliseconds()[0];
  }

  void recordFrame(const SphereDraw& draw, SphereTargets& targets) override {
    VkCommandBuffer cmd = draw.cmd;
    variant_.layout = particleLayoutInfo(draw.particles.layout()).shaderId;
    const Programs& p = programs(variant_);
    gpu::vkCmdFillBuffer(cmd, framebuffer_.handle(), 0, pixels_ * 8, 0xFFFFFFFFu); // kEmptyPixel
    gpu::vkCmdFillBuffer(cmd, chunks_.handle(), 0, kChunkHeaderBytes, 0);
    gpu::vkCmdFillBuffer(cmd, tileBounds_.handle(), 0, tiles_ * 4, 0xFFFFFFFFu); // no bound known
    gpu::vkCmdFillBuffer(cmd, counters_.handle(), 0, kCounterBytes, 0);
    bool culling = variant_.occlusionCull && particlesId_ == draw.particles.id() && batches_ > 0;
    lastCulled_ = culling;
    // With culling, the list drawn first (what the last frame found visible) and the one this frame fills.
    const gpu::Buffer& drawFirst = visibleLists_[current_];
    const gpu::Buffer& nextFirst = visibleLists_[1 - current_];
    if (culling) {
      gpu::vkCmdFillBuffer(cmd, batchList_.handle(), 0, kBatchListHeaderBytes, 0);
      gpu::vkCmdFillBuffer(cmd, nextFirst.handle(), 0, kBatchListHeaderBytes, 0);
      gpu::vkCmdFillBuffer(cmd, hiz_.handle(), tiles_ * 4, coarse_ * 4, 0); // coarse cells: atomicMax
    }
    gpu::fullBarrier(cmd);
    shared::SpherePush push{};
    push.frame = targets.frame.address();
    if (culling) {
      push.particles = drawFirst.address();
      push.groupsX = listGroups_;
      p.rasterList.dispatch(cmd, listGroups_, 1, push);
    } else {
      for (const ParticlePart& part : draw.particles.parts()) {
        gpu::Grid grid = gpu::gridFor(part.count, p.raster.groupSize());
        push.particles = part.data.address();
        push.first = uint32_t(part.first);
        push.count = uint32_t(part.count);
        push.groupsX = grid.x;
        p.raster.dispatch(cmd, grid.x, grid.y, push);
      }
    }
    gpu::fullBarrier(cmd);
    push = {};
    push.frame = targets.frame.address();
    push.groupsX = largeGroups_;
    if (culling) {
      // The depth pyramid needs the tile bounds of the chunks listed so far; the second run below covers
      // the whole list again (a lower bound is idempotent).
      if (variant_.tileBound) {
        p.bound.dispatch(cmd, largeGroups_, 1, push);
        gpu::fullBarrier(cmd);
      }
      p.hiz.dispatch(cmd, tilesX_, tilesY_, push);
      gpu::fullBarrier(cmd);
      gpu::Grid grid = gpu::gridFor(batches_, p.batchCull.groupSize());
      push.particles = nextFirst.address();
      push.groupsX = grid.x;
      p.batchCull.dispatch(cmd, grid.x, grid.y, push);
      gpu::fullBarrier(cmd);
      push.particles = batchList_.address();
      push.groupsX = listGroups_;
      p.rasterList.dispatch(cmd, listGroups_, 1, push);
      gpu::fullBarrier(cmd);
      push.particles = 0;
      push.groupsX = largeGroups_;
      current_ = 1 - current_;
    }
    if (variant_.tileBound) {
      p.bound.dispatch(cmd, largeGroups_, 1, push);
      gpu::fullBarrier(cmd);
    }
    p.cull.dispatch(cmd, largeGroups_, 1, push);
    gpu::fullBarrier(cmd);
    p.large.dispatch(cmd, largeGroups_, 1, push);
    gpu::fullBarrier(cmd);
    recordSphereResolve(cmd, p.resolve, targets.frame.address(), pixels_);
  }

  std::vector<float> depth() override { return readVisibilityDepth(context_, framebuffer_, pixels_); }
  std::vector<uint32_t> indices() override { return readVisibilityIndices(context_, framebuffer_, pixels_); }

  void addCounters(SphereStats& stats) override {
    struct {
      uint64_t count;   // chunks asked for, also past the capacity
      uint32_t spilled; // spheres that drew chunks themselves
      uint32_t drawn;   // chunks left to draw by the cull pass
    } header;
    gpu::readBuffer(context_, chunks_, 0, &header, sizeof header);
    stats.largeChunks = std::min<uint64_t>(header.count, chunkCapacity_);
    stats.spilledSpheres = header.spilled;
    if (lastCulled_) {
      uint32_t late = 0, visible = 0; // list counts: the last frame's second draw, the next frame's first
      gpu::readBuffer(context_, batchList_, 0, &late, 4);
      gpu::readBuffer(context_, visibleLists_[current_], 0, &visible, 4);
      stats.batches = batches_;
      stats.lateBatches = late;
      stats.visibleBatches = visible;
    }
    if (!variant_.countWork) return;
    uint32_t counters[4];
    gpu::readBuffer(context_, counters_, 0, counters, sizeof counters);
    stats.largePixelsTested = counters[0];
    stats.pixelsTested = counters[1];
    stats.depthAtomics = counters[2];
    stats.skippedChunks = counters[3];
  }

private:
  // Pipelines per variant (the layout is specialization constant 0 of every sphere shader).
  const Programs& programs(const Variant& v) {
    auto found = programs_.find(v);
    if (found != programs_.end()) return found->second;
    Programs p;
    p.raster = gpu::ComputeProgram(context_, "sphere_raster.comp",
                                   {{/* LAYOUT= */ 0, v.layout},
                                    {/* COUNT_WORK= */ 3, v.countWork},
                                    {/* TILE_CUT_PIXELS= */ 5, v.tileCutPixels}});
    p.bound = gpu::ComputeProgram(context_, "sphere_tile_bound.comp", {{/* LAYOUT= */ 0, v.layout}});
    p.cull = gpu::ComputeProgram(context_, "sphere_chunk_cull.comp",
                                 {{/* COUNT_WORK= */ 3, v.countWork}, {/* TILE_BOUND= */ 4, v.tileBound}});
    p.large = gpu::ComputeProgram(context_, "sphere_raster_large.comp",
                                  {{/* LAYOUT= */ 0, v.layout}, {/* COUNT_WORK= */ 3, v.countWork}});
    p.resolve = gpu::ComputeProgram(context_, "sphere_resolve.comp", {{/* LAYOUT= */ 0, v.layout}});
    if (v.occlusionCull) {
      p.rasterList = gpu::ComputeProgram(context_, "sphere_raster.comp",
                                         {{/* LAYOUT= */ 0, v.layout},
                                          {/* COUNT_WORK= */ 3, v.countWork},
                                          {/* TILE_CUT_PIXELS= */ 5, v.tileCutPixels},
                                          {/* LIST= */ 6, 1}});
      p.hiz = gpu::ComputeProgram(context_, "sphere_hiz.comp");
      p.batchCull = gpu::ComputeProgram(context_, "sphere_batch_cull.comp");
    }
    return programs_.emplace(v, std::move(p)).first->second;
  }

  gpu::Context& context_;
  uint64_t pixels_;
  gpu::Buffer framebuffer_;
  gpu::Buffer chunks_;
  gpu::Buffer drawnChunks_;
  uint32_t tilesX_;
  uint64_t tiles_;
  gpu::Buffer tileBounds_;
  gpu::Buffer counters_;
  uint32_t tilesY_;
  uint32_t coarseX_;
  uint64_t coarse_;
  gpu::Buffer hiz_;
  // Occlusion culling, for the particle set of id particlesId_ (0: none yet).
  uint64_t particlesId_ = 0;
  uint32_t batches_ = 0;
  uint32_t listGroups_ = 1;
  bool lastCulled_ = false;
  gpu::Buffer batchBounds_, batchFlags_, batchList_;
  gpu::Buffer visibleLists_[2]; // the batches to draw first: visibleLists_[current_] in the next frame
  int current_ = 0;
  uint32_t largeGroups_;
  uint32_t chunkCapacity_ = kDefaultChunkCapacity;
  Variant variant_{};
  std::map<Variant, Programs> programs_;
};

} // namespace

std::unique_ptr<SphereMethodImpl> createSphereComputeMethod(gpu::Context& context, uint32_t width,
                                                            uint32_t height) {
  return std::make_unique<SphereComputeMethod>(context, width, height);
}

} // namespace pointrast
