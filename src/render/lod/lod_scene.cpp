#include "render/lod/lod_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "base/error.h"
#include "base/parallel.h"
#include "base/text.h"
#include "gpu/context.h"
#include "render/lod/node_encoding.h"
#include "render/lod/node_readers.h"
#include "render/lod/page_pool.h"
#include "render/lod/staging.h"

namespace pointrast::lod {

namespace {

constexpr uint64_t kDefaultStagingBytes = uint64_t(256) << 20;
constexpr uint64_t kDefaultUploadBytes = uint64_t(256) << 20;
// Points of one frame or pass are numbered in 32 bits (the visibility index).
constexpr uint64_t kMaxPassPoints = 0xFFFFFFFFull;
// How long the offline loops wait for the readers before looking again.
constexpr double kWaitSeconds = 0.05;

bool finite(const Bounds& b) {
  return std::isfinite(b.min.x) && std::isfinite(b.min.y) && std::isfinite(b.min.z) &&
         std::isfinite(b.max.x) && std::isfinite(b.max.y) && std::isfinite(b.max.z);
}

bool sameCamera(const Camera& a, const Camera& b) {
  return a.eye == b.eye && a.target == b.target && a.up == b.up && a.fovY == b.fovY && a.nearW == b.nearW &&
         a.shiftX == b.shiftX;
}

bool sameViews(std::span<const Camera> a, const std::vector<Camera>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!sameCamera(a[i], b[i])) return false;
  return true;
}

} // namespace

uint64_t defaultGpuBytes(const gpu::Context& context) {
  return context.deviceLocalBytes() / 2;
}

LodScene::LodScene(gpu::Context& context, NodeSource& source, const LodOptions& options)
    : context_(context), source_(source), options_(options) {
  const OctreeMetadata& meta = source.metadata();
  const glm::dvec3 edge = meta.cube.max - meta.cube.min;
  if (!finite(meta.cube) || !(edge.x > 0) || !(edge.y > 0) || !(edge.z > 0))
    throw InputError(meta.source + ": the octree's cube is empty or not finite");
  bounds_ = finite(meta.bounds) && !meta.bounds.empty() ? meta.bounds : meta.cube;
  origin_ = bounds_.center();
  const NodeInfo root = source.root();
  hierarchy_ = std::make_unique<Hierarchy>(meta, root);
  std::vector<PointRecord> sample;
  if (root.pointCount > 0) sample = source.readNode(root);
  if (sample.size() != root.pointCount)
    throw InputError(hierarchy_->describe(0) + " holds " + std::to_string(sample.size()) +
                     " points where its hierarchy says " + std::to_string(root.pointCount));
  encoder_ = std::make_unique<NodeEncoder>(meta, sample, options.colorSource, options.colorRange);
  pool_ = std::make_unique<PagePool>(context, options.gpuBytes ? options.gpuBytes : defaultGpuBytes(context));
  const uint64_t stagingBytes = options.stagingBytes ? options.stagingBytes : kDefaultStagingBytes;
  staging_ = std::make_unique<StagingBlocks>(
      context, uint32_t(std::max<uint64_t>(1, stagingBytes / shared::kLodPageBytes)));
  if (!options_.uploadBytesPerFrame) options_.uploadBytesPerFrame = kDefaultUploadBytes;
  stats_.cacheBytes = pool_->capacity() * shared::kLodPageBytes;
  readers_ = std::make_unique<NodeReaders>(source, *encoder_, *staging_,
                                           options.readers ? options.readers : hardwareThreads(),
                                           options.readerNiceness);
}

LodScene::~LodScene() {
  readers_.reset(); // joins the readers before the staging blocks and the encoder go
}

const OctreeMetadata& LodScene::metadata() const {
  return hierarchy_->metadata();
}

double LodScene::nearW(const Camera& camera) const {
  return camera.nearW > 0 ? camera.nearW : defaultNear(bounds_);
}

void LodScene::collect() {
  std::vector<ReadPoints> points;
  std::vector<ReadChildren> children;
  readers_->collect(points, children);
  for (ReadChildren& c : children) {
    hierarchy_->setChildren(c.id, c.children);
    ++stats_.hierarchyReads;
  }
  for (ReadPoints& p : points)
    arrived_.push_back(std::move(p));
}

void LodScene::touch(uint32_t id) {
  auto found = resident_.find(id);
  if (found == resident_.end()) return;
  found->second.lastUsed = frame_;
  lru_.splice(lru_.end(), lru_, found->second.lru);
}

bool LodScene::residentOrEmpty(uint32_t id) const {
  return hierarchy_->node(id).info.pointCount == 0 || resident_.count(id);
}

void LodScene::checkFits(uint32_t id) const {
  const uint64_t pages = pagesOf(hierarchy_->node(id).info.pointCount);
  const uint64_t bytes = pages * shared::kLodPageBytes;
  if (pages > pool_->capacity())
    throw UnsupportedError(hierarchy_->describe(id) + " needs " + bytesText(bytes) +
                           " of GPU memory, more than the node cache's budget of " +
                           bytesText(pool_->capacity() * shared::kLodPageBytes));
  if (pages > staging_->capacity())
    throw UnsupportedError(
        hierarchy_->describe(id) + " needs " + bytesText(bytes) + " of staging memory, more than the " +
        bytesText(uint64_t(staging_->capacity()) * shared::kLodPageBytes) + " the streaming has");
}

// Evicts least recently used nodes not used in this frame until `pages` pages are free.
bool LodScene::makeRoom(uint64_t pages) {
  while (pool_->free() < pages) {
    if (lru_.empty()) return false;
    const uint32_t id = lru_.front();
    auto found = resident_.find(id);
    if (found->second.lastUsed == frame_) return false; // everything older is gone: the rest is in use
    pool_->release(found->second.pages);
    lru_.pop_front();
    resident_.erase(found);
    ++stats_.nodesEvicted;
  }
  return true;
}

bool LodScene::upload(ReadPoints& read) {
  const uint64_t pages = read.blocks.size();
  if (!makeRoom(pages)) return false;
  Resident r;
  pool_->allocate(pages, r.pages);
  constexpr uint64_t kSection = shared::kLodPageSectionBytes;
  for (uint64_t k = 0; k < pages; ++k) {
    const uint32_t page = r.pages[k];
    const uint64_t from = staging_->offset(read.blocks[k]), to = pool_->offset(page);
    const uint64_t n = std::min<uint64_t>(shared::kLodPagePoints, read.points - k * shared::kLodPagePoints);
    if (n == shared::kLodPagePoints) {
      copies_.push_back({pool_->buffer(page), {from, to, shared::kLodPageBytes}});
    } else { // a node's last page: its four sections up to the last group of four
      for (uint64_t s = 0; s < 4; ++s)
        copies_.push_back(
            {pool_->buffer(page), {from + s * kSection, to + s * kSection, ((n + 3) & ~3ull) * 4}});
    }
  }
  copiedBlocks_.insert(copiedBlocks_.end(), read.blocks.begin(), read.blocks.end());
  r.bounds = read.bounds;
  r.lastUsed = frame_;
  r.lru = lru_.insert(lru_.end(), read.id);
  resident_.emplace(read.id, std::move(r));
  ++stats_.nodesLoaded;
  stats_.bytesStreamed += read.sourceBytes;
  stats_.bytesUploaded += 16 * ((uint64_t(read.points) + 3) & ~3ull); // 4 sections of 4 B a point
  return true;
}

// Uploads arrived nodes that are wanted, most wanted first, until byteLimit bytes were copied (at least one
// node); the rest wait for the next frame. Unwanted ones (the camera moved on) give their blocks back.
void LodScene::uploadArrived(const std::vector<uint32_t>& wanted, uint64_t byteLimit) {
  if (arrived_.empty()) return;
  std::unordered_map<uint32_t, size_t> rank;
  for (size_t i = 0; i < wanted.size(); ++i)
    rank.emplace(wanted[i], i);
  auto rankOf = [&](const ReadPoints& r) {
    auto found = rank.find(r.id);
    return found == rank.end() ? std::numeric_limits<size_t>::max() : found->second;
  };
  std::stable_sort(arrived_.begin(), arrived_.end(),
                   [&](const ReadPoints& a, const ReadPoints& b) { return rankOf(a) < rankOf(b); });
  std::vector<ReadPoints> later;
  uint64_t bytes = 0;
  for (ReadPoints& read : arrived_) {
    if (rankOf(read) == std::numeric_limits<size_t>::max() || resident_.count(read.id)) {
      staging_->give(read.blocks);
    } else if (bytes >= byteLimit) {
      later.push_back(std::move(read));
    } else if (upload(read)) {
      bytes += read.blocks.size() * shared::kLodPageBytes;
    } else {
      staging_->give(read.blocks); // no room this frame: asked for again
    }
  }
  arrived_ = std::move(later);
}

// Asks the readers for the children of `expand` first (they decide what the selection holds), then for the
// points of the wanted nodes that are neither resident nor waiting to be uploaded, most wanted first.
void LodScene::request(const std::vector<uint32_t>& wanted, const std::vector<uint32_t>& expand) {
  std::unordered_set<uint32_t> waiting;
  for (const ReadPoints& r : arrived_)
    waiting.insert(r.id);
  std::vector<ReadJob> jobs;
  for (uint32_t id : expand)
    jobs.push_back({ReadJob::Kind::Children, id, hierarchy_->node(id).info});
  for (uint32_t id : wanted) {
    if (residentOrEmpty(id) || waiting.count(id)) continue;
    checkFits(id);
    jobs.push_back({ReadJob::Kind::Points, id, hierarchy_->node(id).info});
  }
  readers_->want(jobs);
}

void LodScene::buildDrawList(const std::vector<uint32_t>& nodes, uint32_t rankBase) {
  drawList_ = {};
  drawn_ = nodes;
  for (size_t i = 0; i < nodes.size(); ++i) {
    const Resident& r = resident_.at(nodes[i]);
    const glm::dvec3 lo = r.bounds.min - origin_, hi = r.bounds.max - origin_;
    shared::LodNode node{};
    node.min = glm::vec4(glm::vec3(lo), 0.0f);
    node.max = glm::vec4(glm::vec3(hi), 0.0f);
    node.firstIndex = uint32_t(drawList_.points);
    node.pointCount = uint32_t(hierarchy_->node(nodes[i]).info.pointCount);
    node.firstPage = uint32_t(drawList_.pages.size());
    node.rank = rankBase + uint32_t(i);
    for (size_t k = 0; k < r.pages.size(); ++k)
      drawList_.pages.push_back(
          {pool_->address(r.pages[k]), uint32_t(i), uint32_t(k * shared::kLodPagePoints)});
    drawList_.points += node.pointCount;
    drawList_.nodes.push_back(node);
  }
  stats_.nodesDrawn = drawList_.nodes.size();
  stats_.pointsDrawn = drawList_.points;
  stats_.pagesDrawn = drawList_.pages.size();
  stats_.residentBytes = pool_->used() * shared::kLodPageBytes;
}

bool LodScene::update(std::span<const Camera> views, uint32_t width, uint32_t height, const LodView& view) {
  collect();
  ++frame_;
  SelectionLimits limits;
  limits.minNodePx = view.minNodePx;
  limits.foveation = view.foveation;
  limits.pointBudget = std::min(view.pointBudget ? view.pointBudget : kMaxPassPoints, kMaxPassPoints);
  limits.pageBudget = pool_->capacity(); // a frame draws one pass: its selection fits the cache
  const Selection whole = selectNodes(*hierarchy_, views, width, height, origin_, nearW(views[0]), limits);
  stats_.nodesSelected = whole.nodes.size();
  stats_.pointsSelected = whole.points;
  stats_.budgetReached = whole.limited;
  // A rank of a distributed viewer reads and draws its share of the selection; every rank reads the
  // hierarchy the whole selection reaches, so that all select alike.
  const bool shared = options_.shares > 1;
  const Selection sel = shared ? shareOf(whole, *hierarchy_, options_.shareIndex, options_.shares) : whole;
  for (uint32_t id : sel.nodes)
    touch(id);
  uploadArrived(sel.nodes, options_.uploadBytesPerFrame);
  request(sel.nodes, whole.unexpanded);
  // The resident part of the selection, a node only under a drawn parent (parents come first in sel.nodes);
  // a share's parents are often another rank's, so a share draws every resident node of its own.
  std::unordered_set<uint32_t> drawn;
  std::vector<uint32_t> draw;
  for (uint32_t id : sel.nodes) {
    const uint32_t parent = hierarchy_->node(id).parent;
    if (!residentOrEmpty(id) || (!shared && parent != kNoNode && !drawn.count(parent))) continue;
    drawn.insert(id);
    if (hierarchy_->node(id).info.pointCount > 0) draw.push_back(id);
  }
  std::sort(draw.begin(), draw.end(), [&](uint32_t a, uint32_t b) {
    return hierarchy_->node(a).info.key < hierarchy_->node(b).info.key;
  });
  const bool changed = draw != drawn_ || !sameViews(views, lastViews_) || frame_ == 1;
  buildDrawList(draw, 0);
  lastViews_.assign(views.begin(), views.end());
  converged_ = drawn.size() == sel.nodes.size() && whole.unexpanded.empty();
  return changed;
}

void LodScene::recordUploads(VkCommandBuffer cmd) const {
  if (copies_.empty()) return;
  // One command per cache slab, with all its regions.
  std::vector<Copy> sorted = copies_;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const Copy& a, const Copy& b) { return a.target < b.target; });
  std::vector<VkBufferCopy> regions;
  for (size_t i = 0; i < sorted.size(); ++i) {
    regions.push_back(sorted[i].region);
    if (i + 1 == sorted.size() || sorted[i + 1].target != sorted[i].target) {
      gpu::vkCmdCopyBuffer(cmd, staging_->handle(), sorted[i].target, uint32_t(regions.size()),
                           regions.data());
      regions.clear();
    }
  }
  gpu::fullBarrier(cmd);
}

void LodScene::uploadsFinished() {
  staging_->give(copiedBlocks_);
  copiedBlocks_.clear();
  copies_.clear();
}

Selection LodScene::selectAll(std::span<const Camera> views, uint32_t width, uint32_t height,
                              const LodView& view) {
  SelectionLimits limits;
  limits.minNodePx = view.minNodePx;
  limits.pointBudget = view.pointBudget;
  limits.foveation = view.foveation;
  for (;;) {
    collect();
    Selection sel = selectNodes(*hierarchy_, views, width, height, origin_, nearW(views[0]), limits);
    stats_.nodesSelected = sel.nodes.size();
    stats_.pointsSelected = sel.points;
    stats_.budgetReached = sel.limited;
    if (sel.unexpanded.empty())
      return options_.shares > 1 ? shareOf(sel, *hierarchy_, options_.shareIndex, options_.shares) : sel;
    // Points read for earlier frames give their staging blocks back: a reader waiting for blocks must not
    // hold up the hierarchy reads this selection waits for.
    uploadArrived({}, 0);
    request({}, sel.unexpanded);
    readers_->wait(kWaitSeconds);
  }
}

std::vector<std::vector<uint32_t>> LodScene::splitPasses(const Selection& selection) const {
  std::vector<uint32_t> nodes;
  for (uint32_t id : selection.nodes)
    if (hierarchy_->node(id).info.pointCount > 0) nodes.push_back(id);
  std::sort(nodes.begin(), nodes.end(), [&](uint32_t a, uint32_t b) {
    return hierarchy_->node(a).info.key < hierarchy_->node(b).info.key;
  });
  std::vector<std::vector<uint32_t>> passes;
  uint64_t pages = 0, points = 0;
  for (uint32_t id : nodes) {
    checkFits(id);
    const uint64_t n = hierarchy_->node(id).info.pointCount;
    if (passes.empty() || pages + pagesOf(n) > pool_->capacity() || points + n > kMaxPassPoints) {
      passes.emplace_back();
      pages = points = 0;
    }
    passes.back().push_back(id);
    pages += pagesOf(n);
    points += n;
  }
  return passes;
}

void LodScene::makeResident(const std::vector<uint32_t>& pass, uint32_t rankBase) {
  ++frame_;
  for (uint32_t id : pass)
    touch(id);
  for (;;) {
    collect();
    uploadArrived(pass, std::numeric_limits<uint64_t>::max());
    if (!copies_.empty()) {
      context_.submitAndWait([&](VkCommandBuffer cmd) { recordUploads(cmd); });
      uploadsFinished();
    }
    std::vector<uint32_t> missing;
    for (uint32_t id : pass)
      if (!residentOrEmpty(id)) missing.push_back(id);
    if (missing.empty()) break;
    request(missing, {});
    readers_->wait(kWaitSeconds);
  }
  buildDrawList(pass, rankBase);
}

} // namespace pointrast::lod
