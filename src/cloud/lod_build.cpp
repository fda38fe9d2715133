#include "cloud/lod_build.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <optional>
#include <string_view>
#include <thread>

#include "base/cpu_time.h"
#include "base/error.h"
#include "base/parallel.h"
#include "base/progress.h"

namespace pointrast::lod {

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Work units over pieces that never span two pieces: (piece, begin, end).
struct Task {
  size_t piece;
  size_t begin, end;
};
constexpr size_t kTaskPoints = size_t(1) << 18;

std::vector<Task> tasksOf(const Pieces& pieces) {
  std::vector<Task> tasks;
  for (size_t p = 0; p < pieces.size(); ++p)
    for (size_t b = 0; b < pieces[p].size(); b += kTaskPoints)
      tasks.push_back({p, b, std::min(pieces[p].size(), b + kTaskPoints)});
  return tasks;
}

uint64_t totalPoints(const Pieces& pieces) {
  uint64_t n = 0;
  for (const auto& p : pieces)
    n += p.size();
  return n;
}

} // namespace

PhaseClock::PhaseClock() : wall_(Clock::now()), cpu_(processCpuSeconds()) {}

LodPhase PhaseClock::done(std::string name, uint64_t points, uint64_t bytes) const {
  LodPhase p;
  p.name = std::move(name);
  p.seconds = since(wall_);
  p.cpuSeconds = processCpuSeconds() - cpu_;
  p.points = points;
  p.bytes = bytes;
  return p;
}

void checkCancel(const LodRunOptions& options) {
  if (options.cancel && options.cancel->load(std::memory_order_relaxed)) throw Interrupted();
}

void holdForTest(const char* point, const LodRunOptions& options) {
  const char* held = std::getenv("POINTRAST_TEST_HOLD");
  if (!held || std::string_view(held) != point || !options.cancel) return;
  while (!options.cancel->load(std::memory_order_relaxed))
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  throw Interrupted();
}

detail::QuantBox quantBoxOf(const Pieces& pieces, const LodRunOptions& options) {
  const std::vector<Task> tasks = tasksOf(pieces);
  std::vector<detail::QuantBox> boxes(tasks.size());
  parallelBlocksOn(options.threads, tasks.size(), 1, [&](uint64_t t, uint64_t, uint64_t) {
    const Task& task = tasks[t];
    detail::QuantBox box;
    for (size_t i = task.begin; i < task.end; ++i) {
      const PointRecord& r = pieces[task.piece][i];
      const int32_t q[3] = {r.x, r.y, r.z};
      for (int a = 0; a < 3; ++a) {
        box.min[a] = std::min(box.min[a], q[a]);
        box.max[a] = std::max(box.max[a], q[a]);
      }
    }
    boxes[t] = box;
  });
  detail::QuantBox all;
  for (const auto& b : boxes)
    all.expand(b);
  return all;
}

std::vector<uint64_t> countPoints(const LodGrid& grid, const Pieces& pieces, const LodRunOptions& options) {
  std::vector<uint64_t> counts(size_t(1) << 3 * grid.countLevel(), 0);
  const std::vector<Task> tasks = tasksOf(pieces);
  std::optional<Progress> progress;
  if (options.progress) progress.emplace("counting", totalPoints(pieces));
  parallelBlocksOn(options.threads, tasks.size(), 1, [&](uint64_t t, uint64_t, uint64_t) {
    checkCancel(options);
    const Task& task = tasks[t];
    countCells(counts.data(), grid, pieces[task.piece].data() + task.begin, task.end - task.begin);
    if (progress) progress->advance(task.end - task.begin);
  });
  return counts;
}

LargeBuffer<LodItem> distributePoints(const LodGrid& grid, const std::vector<uint64_t>& counts,
                                      Pieces& pieces, const LodRunOptions& options, bool refs) {
  std::vector<uint64_t> pieceFirst(pieces.size() + 1, 0);
  for (size_t p = 0; p < pieces.size(); ++p)
    pieceFirst[p + 1] = pieceFirst[p] + pieces[p].size();
  std::vector<uint64_t> next(counts.size());
  uint64_t total = 0;
  for (size_t c = 0; c < counts.size(); ++c) {
    next[c] = total;
    total += counts[c];
  }
  assert(total == totalPoints(pieces));
  LargeBuffer<LodItem> out(static_cast<size_t>(total));
  const std::vector<Task> tasks = tasksOf(pieces);
  // A piece is freed by the task that finishes it last, so memory drops while the phase runs.
  std::vector<std::atomic<size_t>> remaining(pieces.size());
  for (const Task& task : tasks)
    remaining[task.piece].fetch_add(1, std::memory_order_relaxed);
  const int shift = 3 * (kCodeLevels - grid.countLevel());
  std::optional<Progress> progress;
  if (options.progress) progress.emplace("distributing", total);
  parallelBlocksOn(options.threads, tasks.size(), 1, [&](uint64_t t, uint64_t, uint64_t) {
    checkCancel(options);
    const Task& task = tasks[t];
    const PointRecord* src = pieces[task.piece].data();
    // Codes of a block first, then runs of points in one cell (input is usually spatially coherent)
    // claim their slots at once.
    constexpr size_t kBlock = 512;
    uint64_t codes[kBlock];
    for (size_t b = task.begin; b < task.end; b += kBlock) {
      const size_t n = std::min(kBlock, task.end - b);
      for (size_t i = 0; i < n; ++i)
        codes[i] = grid.code(src[b + i]);
      for (size_t i = 0; i < n;) {
        const uint64_t cell = codes[i] >> shift;
        size_t j = i + 1;
        while (j < n && codes[j] >> shift == cell)
          ++j;
        uint64_t at = std::atomic_ref<uint64_t>(next[cell]).fetch_add(j - i, std::memory_order_relaxed);
        const uint64_t ref = refs ? pieceFirst[task.piece] + b : 0;
        for (; i < j; ++i, ++at)
          out[at] = {codes[i], src[b + i], refs ? ref + i : 0};
      }
    }
    if (progress) progress->advance(task.end - task.begin);
    if (remaining[task.piece].fetch_sub(1, std::memory_order_acq_rel) == 1)
      std::vector<PointRecord>().swap(pieces[task.piece]);
  });
  pieces.clear();
  return out;
}

IndexTimes indexChunks(const std::vector<LodChunk>& chunks, const std::vector<uint64_t>& counts,
                       const ChunkLoader& load, const LodGrid& grid, const LodParams& params,
                       OctreeAssembler& assembler, size_t window, const LodRunOptions& options) {
  const PhaseClock clock;
  IndexTimes times;
  const size_t n = chunks.size();
  uint64_t points = 0;
  for (const LodChunk& c : chunks)
    points += c.points;
  std::optional<Progress> progress;
  if (options.progress) progress.emplace("indexing", points);

  const unsigned threads = static_cast<unsigned>(std::clamp<uint64_t>(
      options.threads ? options.threads : hardwareThreads(), 1, std::max<uint64_t>(n, 1)));
  window = std::max<size_t>(window, threads);
  std::mutex mutex;
  std::condition_variable wake;
  // Chunks claimed for indexing, handed to the assembler (in order), and finished (their buffers back
  // in the pool): nextClaim >= nextWrite >= released.
  size_t nextClaim = 0, nextWrite = 0, released = 0;
  bool writing = false, stop = false;
  std::exception_ptr error;
  std::vector<std::unique_ptr<ChunkNodes>> done(n);
  std::vector<std::unique_ptr<ChunkNodes>> pool; // results written, their buffers kept for reuse

  auto worker = [&] {
    IndexScratch scratch;
    ChunkStorage storage;
    std::unique_lock lock(mutex);
    for (;;) {
      wake.wait(lock, [&] { return stop || nextClaim >= n || nextClaim < released + window; });
      if (stop || nextClaim >= n) return;
      const size_t i = nextClaim++;
      std::unique_ptr<ChunkNodes> result;
      if (!pool.empty()) {
        result = std::move(pool.back());
        pool.pop_back();
      } else {
        result = std::make_unique<ChunkNodes>();
      }
      lock.unlock();
      try {
        checkCancel(options);
        const LoadedChunk loaded = load(i, storage);
        const std::span<LodItem> items = loaded.items;
        const LodChunk& chunk = chunks[i];
        assert(items.size() == chunk.points);
        const uint64_t* cellCounts = counts.data() + chunk.firstCell;
        const size_t cells = static_cast<size_t>(chunk.endCell - chunk.firstCell);
        if (options.indexer)
          options.indexer->index(*result, scratch, grid, chunk.key, items.data(), items.size(), cellCounts,
                                 cells, params, loaded.tails);
        else
          indexChunk(*result, scratch, grid, chunk.key, items.data(), items.size(), cellCounts, cells, params,
                     loaded.tails);
        assembler.prepare(*result);
        if (progress) progress->advance(items.size());
        lock.lock();
        done[i] = std::move(result);
        // Chunks go to the assembler in order, one thread at a time (only their places in the output
        // are decided there); each is then finished (its bytes written) outside that order, on the
        // thread that added it, while another thread may add the next.
        while (!writing && !stop && nextWrite < n && done[nextWrite]) {
          writing = true;
          std::unique_ptr<ChunkNodes> next = std::move(done[nextWrite]);
          lock.unlock();
          const auto addStart = Clock::now();
          assembler.add(*next);
          const double addSeconds = since(addStart);
          lock.lock();
          ++nextWrite;
          writing = false;
          lock.unlock();
          const auto finishStart = Clock::now();
          assembler.finishChunk(*next);
          const double finishSeconds = since(finishStart);
          lock.lock();
          times.writeSeconds += addSeconds + finishSeconds;
          times.orderSeconds += addSeconds;
          pool.push_back(std::move(next));
          ++released;
          wake.notify_all();
        }
      } catch (...) {
        if (!lock.owns_lock()) lock.lock();
        if (!error) error = std::current_exception();
        stop = true;
        wake.notify_all();
        return;
      }
    }
  };
  std::vector<std::thread> pool_threads;
  for (unsigned t = 1; t < threads; ++t)
    pool_threads.emplace_back(worker);
  worker();
  for (auto& t : pool_threads)
    t.join();
  if (error) std::rethrow_exception(error);
  assert(nextWrite == n && released == n);
  const auto finishStart = Clock::now();
  assembler.finish();
  const double finishSeconds = since(finishStart);
  times.writeSeconds += finishSeconds;
  times.orderSeconds += finishSeconds;
  if (progress) progress->finish();
  times.index = clock.done("index", points);
  return times;
}

LodPhase writePhase(const IndexTimes& times, uint64_t points) {
  LodPhase p;
  p.name = "write";
  p.seconds = times.orderSeconds;
  p.threadSeconds = times.writeSeconds;
  p.points = points;
  p.overlapped = true;
  return p;
}

uint64_t inMemoryChunkLimit(uint64_t points, unsigned threads, uint64_t leafPoints) {
  const uint64_t perThread = points / (uint64_t(std::max(threads, 1u)) * 4) + 1;
  return std::max<uint64_t>({leafPoints, 1, std::min<uint64_t>(perThread, uint64_t(1) << 20)});
}

LodBuildStats buildInMemory(Pieces pieces, const LodGrid& grid, const LodParams& params, NodeSink& sink,
                            const LodRunOptions& options, const uint8_t* tails) {
  LodBuildStats stats;
  const uint64_t n = totalPoints(pieces);
  const unsigned threads = options.threads ? options.threads : hardwareThreads();

  PhaseClock clock;
  const std::vector<uint64_t> counts = countPoints(grid, pieces, options);
  stats.phases.push_back(clock.done("count", n));

  clock = PhaseClock();
  const uint64_t chunkLimit = options.chunkPoints ? std::max(options.chunkPoints, params.leafPoints)
                                                  : inMemoryChunkLimit(n, threads, params.leafPoints);
  const std::vector<LodChunk> chunks = planChunks(counts, grid.countLevel(), chunkLimit);
  stats.chunks = chunks.size();
  stats.phases.push_back(clock.done("chunk", n));

  clock = PhaseClock();
  LargeBuffer<LodItem> all = distributePoints(grid, counts, pieces, options, params.tailBytes > 0);
  stats.phases.push_back(clock.done("distribute", n));

  // Chunk i is the contiguous range of its histogram cells in `all`.
  std::vector<uint64_t> firstPoint(chunks.size() + 1, 0);
  for (size_t c = 0; c < chunks.size(); ++c)
    firstPoint[c + 1] = firstPoint[c] + chunks[c].points;
  ChunkLoader load = [&](size_t c, ChunkStorage&) {
    return LoadedChunk{std::span<LodItem>(all.data() + firstPoint[c], static_cast<size_t>(chunks[c].points)),
                       params.tailBytes ? tails : nullptr};
  };
  OctreeAssembler assembler(sink, params.tailBytes);
  const IndexTimes times =
      indexChunks(chunks, counts, load, grid, params, assembler, 2 * size_t(threads), options);
  stats.phases.push_back(times.index);
  stats.phases.push_back(writePhase(times, n));
  stats.octree = assembler.stats();
  return stats;
}

} // namespace pointrast::lod
