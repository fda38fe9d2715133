#include "render/lod/lod_passes.h"

#include <cstring>
#include <span>
#include <vector>

#include "base/error.h"
#include "gpu/context.h"
#include "render/batch_stats.h"

namespace pointrast::lod {

namespace {

constexpr uint64_t kStatsBytes = uint64_t(shared::kBatchStatSlots) * shared::kBatchStatCount * 8;
// Tables: the LodFrame, then nodes, views (GPU only) and pages, each at a multiple of 256 bytes.
constexpr uint64_t kFrameBytes = 256;

uint64_t align256(uint64_t n) {
  return (n + 255) & ~uint64_t(255);
}

struct TableLayout {
  uint64_t nodes, views, pages, end; // offsets in the GPU tables; the upload has no views
  uint64_t uploadPages, uploadEnd;
};

// Stereo frames keep two views a node (shared.h, LodFrame::eyes).
TableLayout layoutOf(uint64_t nodes, uint64_t pages, uint32_t eyes) {
  TableLayout l;
  l.nodes = kFrameBytes;
  l.views = l.nodes + align256(nodes * sizeof(shared::LodNode));
  l.pages = l.views + align256(eyes * nodes * sizeof(shared::LodNodeView));
  l.end = l.pages + align256(pages * sizeof(shared::LodPage));
  l.uploadPages = l.views; // the upload has no views
  l.uploadEnd = l.uploadPages + align256(pages * sizeof(shared::LodPage));
  return l;
}

} // namespace

LodPasses::LodPasses(gpu::Context& context, const MethodInfo& method, uint32_t width, uint32_t height,
                     uint32_t eyes)
    : context_(context), hqs_(method.output == MethodOutput::Blend), eyes_(eyes),
      pixels_(uint64_t(width) * height) {
  const gpu::SpecConstant stereo{/* STEREO= */ 2, eyes == 2 ? 1u : 0u};
  nodes_ = gpu::ComputeProgram(context, "lod_nodes.comp", {stereo});
  // The row's constants: PREFETCH and, for lod-hqs, DEPTH_ONLY (the depth pass before the accumulation).
  raster_ = gpu::ComputeProgram(context, method.shader, method.spec.with({stereo}));
  if (hqs_) {
    accumulate_ = gpu::ComputeProgram(context, "raster_lod_hqs.comp", {stereo});
    resolve_ = gpu::ComputeProgram(context, "resolve_hqs.comp", {{/* ONE_ROUND= */ 0, 1}});
    // hqs1r's accumulators: 1 packed + 2 fallback uint64 per pixel.
    accumulators_ = gpu::Buffer(context, uint64_t(width) * height * 24, gpu::kBufferUsage,
                                gpu::MemoryKind::Device, "lod-hqs accumulators");
  } else {
    resolve_ = gpu::ComputeProgram(context, "resolve_lod.comp", {{/* MODE= */ 0, 0}});
    compose_ = gpu::ComputeProgram(context, "resolve_lod.comp", {{/* MODE= */ 0, 1}});
    finish_ = gpu::ComputeProgram(context, "resolve_lod.comp", {{/* MODE= */ 0, 2}});
  }
  stats_ = gpu::Buffer(context, kStatsBytes, gpu::kBufferUsage, gpu::MemoryKind::Device, "lod statistics");
  statsReadback_ = gpu::Buffer(context, kStatsBytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                               gpu::MemoryKind::Readback, "lod statistics readback");
  setList({});
}

void LodPasses::setList(const LodDrawList& list) {
  nodeCount_ = uint32_t(list.nodes.size());
  pageCount_ = uint32_t(list.pages.size());
  if (!upload_ || list.nodes.size() > capacityNodes_ || list.pages.size() > capacityPages_) {
    // Room for the list and some growth: interactive frames draw lists of slowly changing length.
    capacityNodes_ = std::max<uint64_t>(1024, list.nodes.size() + list.nodes.size() / 2);
    capacityPages_ = std::max<uint64_t>(4096, list.pages.size() + list.pages.size() / 2);
    const TableLayout l = layoutOf(capacityNodes_, capacityPages_, eyes_);
    upload_ = gpu::Buffer(context_, l.uploadEnd, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryKind::Upload,
                          "lod tables upload");
    tables_ = gpu::Buffer(context_, l.end, gpu::kBufferUsage, gpu::MemoryKind::Device, "lod tables");
  }
  const TableLayout l = layoutOf(capacityNodes_, capacityPages_, eyes_);
  auto* base = static_cast<char*>(upload_.mapped());
  std::memcpy(base + l.nodes, list.nodes.data(), list.nodes.size() * sizeof(shared::LodNode));
  std::memcpy(base + l.uploadPages, list.pages.data(), list.pages.size() * sizeof(shared::LodPage));
}

void LodPasses::writeFrame(const Targets& targets, const LodCamera& camera, const RenderSettings& settings,
                           bool nodeStats) {
  const TableLayout l = layoutOf(capacityNodes_, capacityPages_, eyes_);
  shared::LodFrame f{};
  f.framebuffer = targets.framebuffer.address();
  f.stats = stats_.address();
  f.accumulators = hqs_ ? accumulators_.address() : 0;
  f.nodes = tables_.address() + l.nodes;
  f.views = tables_.address() + l.views;
  f.pages = tables_.address() + l.pages;
  f.composite = composite_ ? composite_.address() : 0;
  f.width = targets.eyeWidth();
  f.height = targets.height;
  f.pitch = targets.width;
  f.eyes = eyes_;
  f.rightViewProj = camera.rightViewProj;
  f.clip = targets.scenes.address() + shared::kSceneTableHeader; // the octree's record (Renderer::renderLod)
  f.forcedWords = settings.precision;
  f.culling = settings.batchCulling ? 1 : 0;
  f.nodeCount = nodeCount_;
  f.pageCount = pageCount_;
  f.nodeStats = nodeStats ? 1 : 0;
  std::memcpy(upload_.mapped(), &f, sizeof f);
}

void LodPasses::recordTables(VkCommandBuffer cmd) {
  const TableLayout l = layoutOf(capacityNodes_, capacityPages_, eyes_);
  VkBufferCopy regions[3] = {
      {0, 0, sizeof(shared::LodFrame)},
      {l.nodes, l.nodes, std::max<uint64_t>(1, nodeCount_) * sizeof(shared::LodNode)},
      {l.uploadPages, l.pages, std::max<uint64_t>(1, pageCount_) * sizeof(shared::LodPage)}};
  gpu::vkCmdCopyBuffer(cmd, upload_.handle(), tables_.handle(), 3, regions);
}

void LodPasses::recordStatsCopy(VkCommandBuffer cmd) {
  VkBufferCopy region{0, 0, kStatsBytes};
  gpu::vkCmdCopyBuffer(cmd, stats_.handle(), statsReadback_.handle(), 1, &region);
  gpu::fullBarrier(cmd);
}

void LodPasses::recordNodes(VkCommandBuffer cmd, const LodCamera& camera) {
  if (nodeCount_ == 0) return;
  const gpu::Grid grid = gpu::gridFor(nodeCount_, nodes_.groupSize());
  shared::LodPush push{};
  push.viewProj = camera.viewProj;
  push.frame = tables_.address();
  push.nearW = camera.nearW;
  push.groupsX = grid.x;
  nodes_.dispatch(cmd, grid.x, grid.y, push);
}

void LodPasses::recordPages(VkCommandBuffer cmd, const gpu::ComputeProgram& program,
                            const LodCamera& camera) {
  if (pageCount_ == 0) return;
  const gpu::Grid grid = gpu::gridFor(pageCount_, 1); // one workgroup per page
  shared::LodPush push{};
  push.viewProj = camera.viewProj;
  push.frame = tables_.address();
  push.nearW = camera.nearW;
  push.groupsX = grid.x;
  program.dispatch(cmd, grid.x, grid.y, push);
}

void LodPasses::recordResolve(VkCommandBuffer cmd, const gpu::ComputeProgram& program, const Targets& targets,
                              const RenderSettings& settings, uint64_t aux, bool canonical) {
  shared::ResolvePush push{};
  push.framebuffer = targets.framebuffer.address();
  push.image = targets.image.address();
  push.aux = aux;
  // The resolve stage reads the words (lod-hqs's: the closest depth with the average color); tests read
  // lod's canonical ones.
  const bool words = settings.post.enabled() || (canonical && settings.captureWords);
  push.words = words ? targets.words.address() : 0;
  push.width = targets.width;
  push.height = targets.height;
  push.background = settings.background;
  const gpu::Grid grid = gpu::gridFor(targets.pixels(), program.groupSize());
  push.groupsX = grid.x;
  program.dispatch(cmd, grid.x, grid.y, push);
}

void LodPasses::recordFrame(VkCommandBuffer cmd, const LodCamera& camera, Targets& targets,
                            const RenderSettings& settings) {
  const HqsPass step = hqs_ ? settings.hqsPass : HqsPass::Whole;
  const bool whole = step == HqsPass::Whole, depth = whole || step == HqsPass::Depth;
  const bool blend = hqs_ && (whole || step == HqsPass::Blend);
  writeFrame(targets, camera, settings, true);
  recordTables(cmd);
  if (depth)
    gpu::vkCmdFillBuffer(cmd, targets.framebuffer.handle(), 0, targets.pixels() * 8,
                         0xFFFFFFFFu); // kEmptyPixel
  gpu::vkCmdFillBuffer(cmd, stats_.handle(), 0, VK_WHOLE_SIZE, 0);
  if (blend) gpu::vkCmdFillBuffer(cmd, accumulators_.handle(), 0, VK_WHOLE_SIZE, 0);
  gpu::fullBarrier(cmd);
  if (depth || blend) {
    recordNodes(cmd, camera);
    gpu::fullBarrier(cmd);
  }
  if (depth) {
    recordPages(cmd, raster_, camera);
    gpu::fullBarrier(cmd);
  }
  if (blend) {
    recordPages(cmd, accumulate_, camera);
    gpu::fullBarrier(cmd);
  }
  if (whole || step == HqsPass::Resolve) {
    if (hqs_)
      recordResolve(cmd, resolve_, targets, settings, accumulators_.address(), false);
    else
      recordResolve(cmd, resolve_, targets, settings, tables_.address(), true);
    gpu::fullBarrier(cmd);
  }
  recordStatsCopy(cmd);
}

void LodPasses::recordBegin(VkCommandBuffer cmd, Targets& targets, HqsPass step) {
  gpu::vkCmdFillBuffer(cmd, stats_.handle(), 0, VK_WHOLE_SIZE, 0);
  if (hqs_) {
    if (step == HqsPass::Whole || step == HqsPass::Depth)
      gpu::vkCmdFillBuffer(cmd, targets.framebuffer.handle(), 0, targets.pixels() * 8, 0xFFFFFFFFu);
    if (step == HqsPass::Whole || step == HqsPass::Blend)
      gpu::vkCmdFillBuffer(cmd, accumulators_.handle(), 0, VK_WHOLE_SIZE, 0);
  } else {
    if (!composite_ || composite_.size() < targets.pixels() * shared::kLodCompositeBytes)
      composite_ = gpu::Buffer(context_, targets.pixels() * shared::kLodCompositeBytes, gpu::kBufferUsage,
                               gpu::MemoryKind::Device, "lod composite");
    gpu::vkCmdFillBuffer(cmd, composite_.handle(), 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
  }
  gpu::fullBarrier(cmd);
}

void LodPasses::recordPass(VkCommandBuffer cmd, const LodCamera& camera, Targets& targets,
                           const RenderSettings& settings, LodPhase phase) {
  writeFrame(targets, camera, settings, phase != LodPhase::Blend);
  recordTables(cmd);
  if (phase == LodPhase::Closest)
    gpu::vkCmdFillBuffer(cmd, targets.framebuffer.handle(), 0, targets.pixels() * 8, 0xFFFFFFFFu);
  gpu::fullBarrier(cmd);
  recordNodes(cmd, camera);
  gpu::fullBarrier(cmd);
  recordPages(cmd, phase == LodPhase::Blend ? accumulate_ : raster_, camera);
  gpu::fullBarrier(cmd);
  if (phase == LodPhase::Closest) {
    recordResolve(cmd, compose_, targets, settings, tables_.address(), false);
    gpu::fullBarrier(cmd);
  }
}

void LodPasses::recordFinish(VkCommandBuffer cmd, Targets& targets, const RenderSettings& settings) {
  if (hqs_)
    recordResolve(cmd, resolve_, targets, settings, accumulators_.address(), false);
  else
    recordResolve(cmd, finish_, targets, settings, tables_.address(), true);
  gpu::fullBarrier(cmd);
  recordStatsCopy(cmd);
}

std::vector<uint64_t> LodPasses::readSums() {
  if (!hqs_) throw InternalError("internal error: lod keeps no blend sums");
  return readHqsSums(context_, accumulators_, pixels_, true);
}

void LodPasses::writeSums(std::span<const uint64_t> sums) {
  if (!hqs_) throw InternalError("internal error: lod keeps no blend sums");
  writeHqsSums(context_, accumulators_, pixels_, true, sums);
}

BatchStats LodPasses::readStats() const {
  uint64_t rows[shared::kBatchStatSlots][shared::kBatchStatCount];
  statsReadback_.invalidate();
  std::memcpy(rows, statsReadback_.mapped(), sizeof rows);
  return batchStatsFromRows(rows, hqs_);
}

} // namespace pointrast::lod
