#include "render/gpu_indexer.h"

#include <chrono>
#include <cstddef>
#include <cstring>
#include <vector>

#include "base/error.h"
#include "base/parallel.h"
#include "base/parallel_copy.h"
#include "gpu/context.h"
#include "lod_index_shared.h"

namespace pointrast::render {

namespace shared = pointrast::shared;

// The passes read the builder's items as they are (lod::LodItem) and mark levels as the CPU expects.
static_assert(sizeof(shared::IndexItem) == sizeof(lod::LodItem));
static_assert(offsetof(shared::IndexItem, code) == offsetof(lod::LodItem, code));
static_assert(offsetof(shared::IndexItem, x) == offsetof(lod::LodItem, record) + offsetof(PointRecord, x));
static_assert(offsetof(shared::IndexItem, rg) == offsetof(lod::LodItem, record) + offsetof(PointRecord, rgb));
static_assert(offsetof(shared::IndexItem, bIntensity) ==
              offsetof(lod::LodItem, record) + offsetof(PointRecord, rgb) + 4);
static_assert(offsetof(shared::IndexItem, ref) == offsetof(lod::LodItem, ref));
static_assert(shared::kNotTaken == lod::kNotTakenLevel);
static_assert(shared::kIndexCodeLevels == uint32_t(lod::kCodeLevels));
static_assert(sizeof(shared::RadixPush) == 64);
static_assert(sizeof(shared::IndexLevelPush) == 112 && offsetof(shared::IndexLevelPush, qmin) == 56 &&
              offsetof(shared::IndexLevelPush, count) == 68 && offsetof(shared::IndexLevelPush, cells) == 96);
// The cells' sums (IndexLevelPush::cells): 8 + 24 + 4 + 4 + 4 bytes a point, then the equal-codes flag.
constexpr uint64_t kCellBytesPerPoint = 44;
constexpr uint64_t kFlagBytes = 16;
// Staging down: the order and the sorted points after the sort; the levels and colors after the passes.
constexpr uint64_t kDownloadBytesPerPoint = sizeof(uint32_t) + sizeof(lod::LodItem);

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

} // namespace

GpuIndexer::GpuIndexer(gpu::Context& context)
    : context_(context), histogram_(context, "lod_index_histogram.comp"),
      scan_(context, "lod_index_scan.comp"), scatter_(context, "lod_index_scatter.comp"),
      gather_(context, "lod_index_gather.comp"), cells_(context, "lod_index_cells.comp"),
      best_(context, "lod_index_best.comp"), level_(context, "lod_index_level.comp") {
  for (size_t i = 0; i < kSlots; ++i) {
    slots_.push_back(std::make_unique<Slot>());
    free_.push_back(slots_.back().get());
  }
}

GpuIndexer::~GpuIndexer() = default;

GpuIndexer::Stats GpuIndexer::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

// One chunk's buffers: on the device, and staging kept from chunk to chunk.
struct GpuIndexer::Slot {
  size_t capacity = 0;
  gpu::Buffer items, sorted, keys[2], values[2], taken, colors, cells, buckets;
  gpu::Buffer upload, download;

  void reserve(gpu::Context& context, size_t count) {
    if (count <= capacity) return;
    // Room for a quarter more than asked, so that chunks a little larger do not reallocate each time.
    const size_t n = count + count / 4;
    const uint64_t tiles = (n + shared::kRadixTileItems - 1) / shared::kRadixTileItems;
    capacity = 0;
    auto make = [&](uint64_t bytes, gpu::MemoryKind kind, const char* name) {
      return gpu::Buffer(context, bytes, gpu::kBufferUsage, kind, name);
    };
    // The old buffers go first: their memory may be needed for the new ones.
    for (gpu::Buffer* b : {&items, &sorted, &keys[0], &keys[1], &values[0], &values[1], &taken, &colors,
                           &cells, &buckets, &upload, &download})
      *b = gpu::Buffer();
    const gpu::MemoryKind device = gpu::MemoryKind::Device;
    items = make(n * sizeof(lod::LodItem), device, "index items");
    sorted = make(n * sizeof(lod::LodItem), device, "index sorted items");
    for (int b = 0; b < 2; ++b) {
      keys[b] = make(n * sizeof(uint64_t), device, "index keys");
      values[b] = make(n * sizeof(uint32_t), device, "index order");
    }
    taken = make(n * sizeof(uint32_t), device, "index taken levels");
    colors = make(n * 2 * sizeof(uint32_t), device, "index colors");
    cells = make(n * kCellBytesPerPoint + kFlagBytes, device, "index cells");
    buckets = make(tiles * 256 * sizeof(uint32_t), device, "index histogram");
    // The items (or the order) up; the order and the sorted points, or the levels and colors, down.
    upload = make(n * sizeof(lod::LodItem), gpu::MemoryKind::Upload, "index upload");
    download = make(n * kDownloadBytesPerPoint + kFlagBytes, gpu::MemoryKind::Readback, "index download");
    capacity = n;
  }
};

GpuIndexer::Slot& GpuIndexer::acquire() {
  std::unique_lock lock(mutex_);
  freed_.wait(lock, [&] { return !free_.empty(); });
  Slot* slot = free_.back();
  free_.pop_back();
  return *slot;
}

void GpuIndexer::release(Slot& slot) {
  {
    std::lock_guard lock(mutex_);
    free_.push_back(&slot);
  }
  freed_.notify_one();
}

void GpuIndexer::submit(const std::function<void(VkCommandBuffer)>& record) {
  std::lock_guard lock(deviceMutex_);
  const auto start = Clock::now();
  context_.submitAndWait(record);
  const double seconds = since(start);
  std::lock_guard statsLock(mutex_);
  stats_.busySeconds += seconds;
}

namespace {

void copyBuffer(VkCommandBuffer cmd, const gpu::Buffer& from, const gpu::Buffer& to, uint64_t toOffset,
                uint64_t size, uint64_t fromOffset = 0) {
  const VkBufferCopy region{fromOffset, toOffset, size};
  gpu::vkCmdCopyBuffer(cmd, from.handle(), to.handle(), 1, &region);
}

} // namespace

bool GpuIndexer::indexOnDevice(const lod::LodGrid& grid, const lod::NodeKey& chunk, lod::LodItem* items,
                               size_t count, const lod::LodParams& params, uint32_t* levels,
                               uint32_t* colors) {
  const auto asked = Clock::now();
  Slot& slot = acquire();
  struct Release {
    GpuIndexer& indexer;
    Slot& slot;
    ~Release() { indexer.release(slot); }
  } releaseLater{*this, slot};
  Stats times;
  times.waitSeconds = since(asked);
  try {
    slot.reserve(context_, count);
  } catch (const UnsupportedError&) {
    return false;
  }
  const auto start = Clock::now();
  copyOnAllThreads(slot.upload.mapped(), items, count * sizeof(lod::LodItem));
  auto step = Clock::now();
  // Adds the time since the last step's end to `seconds`.
  auto lap = [&](double& seconds) {
    const auto now = Clock::now();
    seconds += std::chrono::duration<double>(now - step).count();
    step = now;
  };
  times.stageSeconds = since(start);

  // Up, then the radix sort on the bits the chunk's codes may differ in, 8 at a time from the lowest:
  // stable passes, so the points end sorted by code, equal codes in the order they came. The points
  // gathered in that order; the order and the sorted points down.
  const uint32_t n = static_cast<uint32_t>(count);
  const uint32_t tiles = (n + shared::kRadixTileItems - 1) / shared::kRadixTileItems;
  const int freeBits = 3 * (lod::kCodeLevels - chunk.level);
  const int passes = (freeBits + int(shared::kRadixBits) - 1) / int(shared::kRadixBits);
  const gpu::Grid tileGrid = gpu::gridFor(uint64_t(tiles) * shared::kIndexGroupSize, shared::kIndexGroupSize);
  const int current = passes % 2; // the slot.keys/slot.values pair the last pass writes

  shared::IndexLevelPush push{};
  push.items = slot.items.address();
  push.order = slot.values[current].address();
  push.sorted = slot.sorted.address();
  push.taken = slot.taken.address();
  push.colors = slot.colors.address();
  push.cells = slot.cells.address();
  push.keys = slot.keys[current].address();
  push.leafPoints = params.leafPoints;
  push.edgeQuanta = grid.edgeQuanta;
  for (int a = 0; a < 3; ++a)
    push.qmin[a] = grid.qmin[a];
  push.count = n;
  push.chunkLevel = uint32_t(chunk.level);
  push.averageColors = params.averageColors ? 1u : 0u;
  const gpu::Grid pointGrid = gpu::gridFor(count, shared::kIndexGroupSize);
  push.groupsX = pointGrid.x;
  const uint64_t orderBytes = count * sizeof(uint32_t), itemBytes = count * sizeof(lod::LodItem);
  const uint64_t flagOffset = count * kCellBytesPerPoint; // in the cells' buffer and in staging

  submit([&](VkCommandBuffer cmd) {
    gpu::fullBarrier(cmd);
    copyBuffer(cmd, slot.upload, slot.items, 0, itemBytes);
    gpu::fullBarrier(cmd);
    for (int p = 0; p < passes; ++p) {
      shared::RadixPush radix{};
      const int in = p % 2, out = 1 - in;
      radix.keysIn = slot.keys[in].address();
      radix.valuesIn = slot.values[in].address();
      radix.keysOut = slot.keys[out].address();
      radix.valuesOut = slot.values[out].address();
      radix.histogram = slot.buckets.address();
      radix.items = p == 0 ? slot.items.address() : 0; // the first pass reads the codes from the items
      radix.count = n;
      radix.shift = uint32_t(p) * shared::kRadixBits;
      radix.tiles = tiles;
      radix.groupsX = tileGrid.x;
      histogram_.dispatch(cmd, tileGrid.x, tileGrid.y, radix);
      gpu::fullBarrier(cmd);
      scan_.dispatch(cmd, 1, 1, radix);
      gpu::fullBarrier(cmd);
      scatter_.dispatch(cmd, tileGrid.x, tileGrid.y, radix);
      gpu::fullBarrier(cmd);
    }
    gpu::vkCmdFillBuffer(cmd, slot.cells.handle(), flagOffset, sizeof(uint32_t), 0);
    gpu::fullBarrier(cmd);
    gather_.dispatch(cmd, pointGrid.x, pointGrid.y, push);
    gpu::fullBarrier(cmd);
    copyBuffer(cmd, slot.values[current], slot.download, 0, orderBytes);
    copyBuffer(cmd, slot.sorted, slot.download, orderBytes, itemBytes);
    copyBuffer(cmd, slot.cells, slot.download, flagOffset, sizeof(uint32_t), flagOffset);
    gpu::fullBarrier(cmd);
  });
  slot.download.invalidate();
  const auto* down = static_cast<const uint8_t*>(slot.download.mapped());
  uint32_t equalCodes = 0;
  std::memcpy(&equalCodes, down + flagOffset, sizeof equalCodes);
  copyOnAllThreads(items, down + orderBytes, itemBytes);
  lap(times.sortSeconds);

  // Equal codes into canonical order (by record bytes, then ref), on the CPU, where the gather found
  // any: they are few. The items end sorted in place, as indexChunk leaves them; where the order changed
  // it goes up and the points are gathered again.
  bool reordered = false;
  if (equalCodes != 0) {
    std::vector<uint32_t> order(count);
    copyOnAllThreads(order.data(), down, orderBytes);
    reordered = lod::orderEqualCodes(items, order.data(), count);
    if (reordered) copyOnAllThreads(slot.upload.mapped(), order.data(), orderBytes);
  }
  lap(times.orderSeconds);

  push.keys = 0; // the flag is read already
  // Each level's subsample from the root down, three passes a level (levels whose nodes are all leaves
  // find nothing to take), then the levels and colors down.
  submit([&](VkCommandBuffer cmd) {
    if (reordered) {
      gpu::fullBarrier(cmd);
      copyBuffer(cmd, slot.upload, slot.values[current], 0, orderBytes);
      gpu::fullBarrier(cmd);
      gather_.dispatch(cmd, pointGrid.x, pointGrid.y, push);
    }
    gpu::fullBarrier(cmd);
    for (int level = 0; level < lod::kMaxLevel; ++level) {
      push.level = uint32_t(level);
      push.cellLevel = uint32_t(grid.sampleLevel(level));
      for (gpu::ComputeProgram* pass : {&cells_, &best_, &level_}) {
        pass->dispatch(cmd, pointGrid.x, pointGrid.y, push);
        gpu::fullBarrier(cmd);
      }
    }
    copyBuffer(cmd, slot.taken, slot.download, 0, orderBytes);
    copyBuffer(cmd, slot.colors, slot.download, orderBytes, 2 * orderBytes);
    gpu::fullBarrier(cmd);
  });
  slot.download.invalidate();
  lap(times.levelSeconds);
  copyOnAllThreads(levels, down, orderBytes);
  copyOnAllThreads(colors, down + orderBytes, 2 * orderBytes);
  lap(times.readSeconds);
  times.deviceSeconds = since(start);
  times.gpuChunks = 1;
  times.gpuPoints = count;
  std::lock_guard lock(mutex_);
  stats_ += times;
  return true;
}

void GpuIndexer::index(lod::ChunkNodes& out, lod::IndexScratch& scratch, const lod::LodGrid& grid,
                       const lod::NodeKey& chunk, lod::LodItem* items, size_t count,
                       const uint64_t* cellCounts, size_t cells, const lod::LodParams& params,
                       const uint8_t* tails) {
  if (grid.isotropic && count > 0 && count < size_t(UINT32_MAX)) {
    std::vector<uint32_t> levels(count), colors(2 * count);
    if (indexOnDevice(grid, chunk, items, count, params, levels.data(), colors.data())) {
      lod::assembleIndexedChunk(out, chunk, items, count, levels.data(), colors.data(), params, tails);
      return;
    }
  }
  lod::indexChunk(out, scratch, grid, chunk, items, count, cellCounts, cells, params, tails);
  std::lock_guard lock(mutex_);
  ++stats_.cpuChunks;
  stats_.cpuPoints += count;
}

} // namespace pointrast::render
