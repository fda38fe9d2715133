#include "io/potree/lod_builder.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <mutex>
#include <optional>
#include <thread>

#include <unistd.h>

#include "base/error.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "cloud/cloud.h"
#include "io/io_util.h"
#include "io/potree/lod_inputs.h"
#include "io/potree/lod_spill.h"

namespace pointrast::io {

using namespace detail;

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Bytes a point costs in memory: its item (40 B: code, record and tail ref) and about 8 B of read records
// not yet freed while they are distributed (each input piece is freed as soon as it is distributed).
// Measured peaks (resident): 42 B a point for 1 G points of point format 2 on 16 threads, 53 B for 20 M
// on 2 threads and 75 B for 15 M points with 20 B of attributes a point on 2 threads (their chunks' index
// buffers included); this estimate, with the per-thread term below, is 25-35 % above each.
constexpr uint64_t kInMemoryBytesPerPoint = 48;
// Bytes a chunk point costs a thread that indexes it out of core (records read 24 B, items 32 B, a
// cell's sort buffer up to 32 B, output 24 B).
constexpr uint64_t kIndexBytesPerPoint = 112;
constexpr uint64_t kFixedBytes = uint64_t(64) << 20; // histograms, chunk tables, I/O buffers

uint64_t readMemInfo(const char* key) {
  std::ifstream in("/proc/meminfo");
  std::string name;
  uint64_t kb = 0;
  std::string unit;
  while (in >> name >> kb >> unit)
    if (name == key) return kb * 1024;
  return 0;
}

uint64_t cgroupLimit() {
  std::ifstream in("/sys/fs/cgroup/memory.max"); // cgroup v2; "max" when unlimited
  uint64_t bytes = 0;
  if (in >> bytes) return bytes;
  return 0;
}

// Runs body(worker) on `threads` threads; the first exception is rethrown after all have stopped.
template <class Body> void runWorkers(unsigned threads, Body&& body) {
  std::exception_ptr error;
  std::mutex mutex;
  auto guarded = [&](unsigned t) {
    try {
      body(t);
    } catch (...) {
      std::lock_guard lock(mutex);
      if (!error) error = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t)
    pool.emplace_back(guarded, t);
  guarded(0);
  for (auto& t : pool)
    t.join();
  if (error) std::rethrow_exception(error);
}

// An octree the renderer could not draw (coordinates past kMaxCoordinate) is refused once its points
// were scanned, before a node is written; a scale that alone puts them there is named, since a damaged
// header's scale is the usual cause.
void checkOctreeFrame(const Bounds& bounds, const glm::dvec3& scale, const std::string& source) {
  // 2^31: the largest magnitude of a record's int32 coordinate.
  const double largestScale = std::max({scale.x, scale.y, scale.z});
  if (!(largestScale * 2147483648.0 <= kMaxCoordinate)) {
    try {
      checkCoordinateRange(bounds, source);
    } catch (const InputError&) {
      throw InputError(strFormat("%s: a scale of %.3g puts coordinates beyond the %.0e pointrast renders; a "
                                 "damaged header?",
                                 source.c_str(), largestScale, kMaxCoordinate));
    }
  }
  checkCoordinateRange(bounds, source);
}

} // namespace

uint64_t defaultBuildMemory() {
  uint64_t total = readMemInfo("MemTotal:");
  const uint64_t limit = cgroupLimit();
  if (limit && (total == 0 || limit < total)) total = limit;
  if (total == 0) total = uint64_t(8) << 30; // unknown: assume a small machine
  return total / 2;
}

struct OctreeBuilder::State {
  LodBuildOptions options;
  BuildInputs inputs;
  unsigned threads = 1;
  lod::LodRunOptions run;
  lod::LodParams params;
  uint64_t memory = 0;
  uint64_t inMemoryChunk = 0;
  bool inMemory = true;
  bool scanned = false;
  lod::Pieces pieces;         // in memory: every point, after scan()
  LargeBuffer<uint8_t> tails; // in memory: every point's tail, in task order, after scan()
  lod::LodGrid grid;
  lod::OctreeMetadata metadata;
  std::vector<lod::LodPhase> phases;
  Clock::time_point start;

  State(const std::vector<std::filesystem::path>& paths, const LodBuildOptions& o)
      : options(o), inputs(paths) {}

  // The constants above, plus a tail per point where points carry tails (a tail is held twice while
  // indexing, in the chunk's store and its nodes', which the per-thread term counts).
  uint64_t inMemoryBytesPerPoint() const { return kInMemoryBytesPerPoint + params.tailBytes; }
  uint64_t indexBytesPerPoint() const {
    return kIndexBytesPerPoint + (params.tailBytes ? 16 + 3 * uint64_t(params.tailBytes) : 0);
  }

  unsigned readThreads() const {
    return std::min<unsigned>(threads, static_cast<unsigned>(std::max<size_t>(inputs.tasks().size(), 1)));
  }

  // Calls fn(worker, task, records) for every piece on readThreads() workers; records is the worker's
  // buffer.
  template <class Fn> void readAll(const char* label, Fn&& fn) {
    const auto& tasks = inputs.tasks();
    std::optional<Progress> progress;
    if (options.progress) progress.emplace(label, inputs.points());
    std::atomic<size_t> next{0};
    runWorkers(readThreads(), [&](unsigned worker) {
      std::vector<PointRecord> records;
      for (size_t t; (t = next.fetch_add(1)) < tasks.size();) {
        lod::checkCancel(run);
        fn(worker, t, records);
        if (progress) progress->advance(tasks[t].points);
      }
    });
    if (progress) progress->finish();
  }
};

OctreeBuilder::OctreeBuilder(const std::vector<std::filesystem::path>& inputs, const LodBuildOptions& options)
    : state_(std::make_unique<State>(inputs, options)) {
  State& s = *state_;
  s.threads = options.threads ? options.threads : hardwareThreads();
  s.run.threads = s.threads;
  s.run.cancel = options.cancel;
  s.run.progress = options.progress;
  s.run.indexer = options.indexer;
  s.params.leafPoints = std::max<uint64_t>(options.leafPoints, 1);
  s.params.averageColors = options.averageColors;
  s.params.tailBytes = s.inputs.tail().bytes();
  s.memory = options.memoryBytes ? options.memoryBytes : defaultBuildMemory();
  const uint64_t n = s.inputs.points();
  s.inMemoryChunk = lod::inMemoryChunkLimit(n, s.threads, s.params.leafPoints);
  const uint64_t need = n * s.inMemoryBytesPerPoint() +
                        uint64_t(s.threads) * s.inMemoryChunk * s.indexBytesPerPoint() + kFixedBytes;
  s.inMemory = need <= s.memory;
}

OctreeBuilder::~OctreeBuilder() = default;

uint64_t OctreeBuilder::points() const {
  return state_->inputs.points();
}
bool OctreeBuilder::inMemory() const {
  return state_->inMemory;
}
const TailFormat& OctreeBuilder::tail() const {
  return state_->inputs.tail();
}

const lod::OctreeMetadata& OctreeBuilder::scan() {
  State& s = *state_;
  if (s.scanned) return s.metadata;
  s.start = Clock::now();
  const lod::PhaseClock readClock;
  const auto& tasks = s.inputs.tasks();
  std::vector<BuildInputs::Scan> scans(tasks.size());
  // Tails are read whole, then fields that are zero everywhere are left out (BuildInputs::pruneTail).
  const uint32_t readTailBytes = s.inputs.tail().bytes();
  std::vector<std::vector<uint8_t>> masks(s.readThreads(), std::vector<uint8_t>(readTailBytes, 0));
  std::vector<uint8_t> mask(readTailBytes, 0);
  std::vector<char> returnsDiffer(masks.size(), 0);
  auto pruneTail = [&] {
    bool differ = false;
    for (size_t w = 0; w < masks.size(); ++w) {
      for (uint32_t b = 0; b < readTailBytes; ++b)
        mask[b] |= masks[w][b];
      differ = differ || returnsDiffer[w];
    }
    const TailFormat full = s.inputs.pruneTail(mask, differ);
    s.params.tailBytes = s.inputs.tail().bytes();
    return full;
  };
  if (s.inMemory) {
    s.pieces.resize(tasks.size());
    std::vector<std::vector<uint8_t>> pieceTails(tasks.size());
    s.readAll("reading", [&](unsigned worker, size_t t, std::vector<PointRecord>&) {
      if (readTailBytes) {
        s.inputs.read(tasks[t], s.pieces[t], pieceTails[t]);
        if (s.pieces[t].size() != tasks[t].points)
          fail(s.inputs.names(), "a file changed while the octree was built");
        bool differ = returnsDiffer[worker];
        s.inputs.orTails(s.pieces[t].data(), pieceTails[t].data(), s.pieces[t].size(), masks[worker].data(),
                         differ);
        returnsDiffer[worker] = differ;
      } else {
        s.inputs.read(tasks[t], s.pieces[t]);
      }
      scans[t] = BuildInputs::scan(s.pieces[t]);
    });
    const TailFormat full = pruneTail();
    const uint32_t tailBytes = s.params.tailBytes;
    if (tailBytes) {
      std::vector<uint64_t> first(tasks.size() + 1, 0);
      for (size_t t = 0; t < tasks.size(); ++t)
        first[t + 1] = first[t] + tasks[t].points;
      s.tails = LargeBuffer<uint8_t>(static_cast<size_t>(first.back() * tailBytes));
      parallelBlocksOn(s.threads, tasks.size(), 1, [&](uint64_t t, uint64_t, uint64_t) {
        BuildInputs::repack(full, s.inputs.tail(), pieceTails[t].data(), tasks[t].points,
                            s.tails.data() + first[t] * tailBytes);
        std::vector<uint8_t>().swap(pieceTails[t]);
      });
    }
    if (s.inputs.decideColors(scans))
      parallelBlocksOn(s.threads, tasks.size(), 1,
                       [&](uint64_t t, uint64_t, uint64_t) { s.inputs.widen(tasks[t], s.pieces[t]); });
  } else {
    s.readAll("scanning", [&](unsigned worker, size_t t, std::vector<PointRecord>& records) {
      if (readTailBytes) {
        thread_local std::vector<uint8_t> tails;
        s.inputs.read(tasks[t], records, tails);
        bool differ = returnsDiffer[worker];
        s.inputs.orTails(records.data(), tails.data(), records.size(), masks[worker].data(), differ);
        returnsDiffer[worker] = differ;
      } else {
        s.inputs.read(tasks[t], records);
      }
      scans[t] = BuildInputs::scan(records);
    });
    pruneTail();
    s.inputs.decideColors(scans);
  }
  pointrast::detail::QuantBox box;
  for (const auto& scan : scans)
    box.expand(scan.box);
  if (box.empty()) throw InputError(s.inputs.names() + ": no points to build an octree from");
  const lod::LodGrid first = lod::makeLodGrid(box, s.inputs.scale(), s.inputs.offset());
  s.grid =
      lod::makeLodGrid(box, s.inputs.scale(), s.inputs.offset(),
                       lod::gridLevelsForSpacing(first.cube.max.x - first.cube.min.x, s.options.spacing));
  s.phases.push_back(readClock.done("read", s.inputs.points(), s.inputs.fileBytes()));

  lod::OctreeMetadata& m = s.metadata;
  m.source = s.inputs.names();
  m.cube = s.grid.cube;
  m.bounds = pointrast::detail::worldBounds(box, s.grid.scale, s.grid.offset);
  checkOctreeFrame(m.bounds, s.grid.scale, s.inputs.names());
  m.spacing = s.grid.spacing();
  m.scale = s.grid.scale;
  m.offset = s.grid.offset;
  m.pointCount = s.inputs.points();
  m.fields = s.inputs.fields();
  s.scanned = true;
  return m;
}

LodBuildReport OctreeBuilder::build(lod::NodeSink& sink, const std::filesystem::path& tempDir) {
  State& s = *state_;
  scan();
  LodBuildReport report;
  report.outOfCore = !s.inMemory;
  report.memoryBytes = s.memory;
  report.threads = s.threads;
  report.inputBytes = s.inputs.fileBytes();
  const uint64_t n = s.inputs.points();
  const lod::LodGrid& grid = s.grid;

  if (s.inMemory) {
    lod::LodBuildStats stats = lod::buildInMemory(std::move(s.pieces), grid, s.params, sink, s.run,
                                                  s.params.tailBytes ? s.tails.data() : nullptr);
    s.tails = LargeBuffer<uint8_t>();
    s.phases.insert(s.phases.end(), stats.phases.begin(), stats.phases.end());
    report.octree = stats.octree;
    report.chunks = stats.chunks;
  } else {
    const auto& tasks = s.inputs.tasks();
    lod::PhaseClock clock;
    std::vector<uint64_t> counts(size_t(1) << 3 * grid.countLevel(), 0);
    s.readAll("counting", [&](unsigned, size_t task, std::vector<PointRecord>& records) {
      s.inputs.read(tasks[task], records);
      lod::countCells(counts.data(), grid, records.data(), records.size());
    });
    s.phases.push_back(clock.done("count", n, s.inputs.fileBytes()));

    clock = lod::PhaseClock();
    // A chunk, indexed by one thread, may take its share of the memory bound.
    const uint64_t chunkLimit = std::max<uint64_t>(
        s.params.leafPoints, s.memory / (uint64_t(s.threads) * s.indexBytesPerPoint() * 2));
    const std::vector<lod::LodChunk> chunks = lod::planChunks(counts, grid.countLevel(), chunkLimit);
    const std::vector<uint32_t> chunkOf = lod::chunkOfCell(chunks, grid.countLevel());
    uint64_t largest = 0;
    for (const auto& c : chunks)
      largest = std::max(largest, c.points);
    if (largest > chunkLimit)
      warn(s.inputs.names(),
           strFormat(
               "one cell of the cube holds %s points, more than the memory bound allows one chunk to hold; "
               "it is indexed in memory anyway",
               humanCount(double(largest)).c_str()));
    report.chunks = chunks.size();
    s.phases.push_back(clock.done("chunk", n));

    clock = lod::PhaseClock();
    const uint32_t tailBytes = s.params.tailBytes;
    ChunkSpill spill(tempDir, chunks.size(), tailBytes);
    std::vector<uint64_t> first(tasks.size() + 1, 0);
    for (size_t t = 0; t < tasks.size(); ++t)
      first[t + 1] = first[t] + tasks[t].points;
    const uint64_t bufferBytes =
        std::clamp<uint64_t>(s.memory / (4 * uint64_t(s.threads)), 1 << 16, 64 << 20);
    const int shift = 3 * (lod::kCodeLevels - grid.countLevel());
    {
      std::vector<std::unique_ptr<ChunkSpill::Writer>> writers;
      for (unsigned w = 0; w < s.readThreads(); ++w)
        writers.push_back(std::make_unique<ChunkSpill::Writer>(spill, bufferBytes));
      s.readAll("distributing", [&](unsigned worker, size_t task, std::vector<PointRecord>& records) {
        ChunkSpill::Writer* writer = writers[worker].get();
        if (tailBytes) {
          thread_local std::vector<uint8_t> tails;
          s.inputs.read(tasks[task], records, tails);
          for (size_t i = 0; i < records.size(); ++i)
            writer->add(chunkOf[grid.countCell(records[i])], records[i], first[task] + i,
                        tails.data() + i * tailBytes);
        } else {
          s.inputs.read(tasks[task], records);
          for (const PointRecord& r : records)
            writer->add(chunkOf[grid.countCell(r)], r);
        }
      });
      for (auto& w : writers)
        w->flush();
    }
    s.phases.push_back(clock.done("distribute", n, s.inputs.fileBytes() + spill.bytesWritten()));
    lod::holdForTest("chunks-written", s.run);

    const size_t window = std::clamp<size_t>(
        s.memory / std::max<uint64_t>(1, largest * s.indexBytesPerPoint()), 1, 2 * size_t(s.threads));
    lod::ChunkLoader load = [&](size_t c, lod::ChunkStorage& storage) {
      const lod::LodChunk& chunk = chunks[c];
      std::vector<lod::LodItem>& items = storage.items;
      thread_local std::vector<uint8_t> rows;
      spill.read(c, chunk.points, rows);
      const size_t rowBytes = spill.rowBytes();
      const size_t count = static_cast<size_t>(chunk.points);
      // With tails: the chunk's tail store in input order (by each point's place), so that a ref, the
      // index into it, orders equal records as the input does whatever order the file holds them in.
      thread_local std::vector<uint64_t> rank;
      if (tailBytes) {
        thread_local std::vector<std::pair<uint64_t, uint64_t>> places;
        places.resize(count);
        for (size_t i = 0; i < count; ++i) {
          uint64_t place;
          std::memcpy(&place, rows.data() + i * rowBytes + sizeof(PointRecord), sizeof place);
          places[i] = {place, uint64_t(i)};
        }
        std::sort(places.begin(), places.end());
        rank.resize(count);
        storage.tails.resize(count * tailBytes);
        for (size_t k = 0; k < count; ++k) {
          rank[places[k].second] = k;
          std::memcpy(storage.tails.data() + k * tailBytes,
                      rows.data() + places[k].second * rowBytes + sizeof(PointRecord) + sizeof(uint64_t),
                      tailBytes);
        }
      }
      // Grouped by histogram cell, the layout indexChunk takes (as distributePoints makes in memory).
      std::vector<uint64_t> next(static_cast<size_t>(chunk.endCell - chunk.firstCell));
      uint64_t at = 0;
      for (size_t i = 0; i < next.size(); ++i) {
        next[i] = at;
        at += counts[chunk.firstCell + i];
      }
      items.resize(count);
      auto changed = [&] { fail(spill.dir(), "a temporary chunk file changed while the octree was built"); };
      for (size_t i = 0; i < count; ++i) {
        PointRecord r;
        std::memcpy(&r, rows.data() + i * rowBytes, sizeof r);
        const uint64_t code = grid.code(r);
        const uint64_t cell = (code >> shift) - chunk.firstCell;
        if (cell >= next.size() || next[cell] >= items.size()) changed();
        items[next[cell]++] = {code, r, tailBytes ? rank[i] : uint64_t(0)};
      }
      for (size_t i = 0; i < next.size(); ++i)
        if (next[i] != (i + 1 < next.size() ? next[i + 1] - counts[chunk.firstCell + i + 1] : items.size()))
          changed();
      return lod::LoadedChunk{std::span<lod::LodItem>(items), tailBytes ? storage.tails.data() : nullptr};
    };
    lod::OctreeAssembler assembler(sink, tailBytes);
    const lod::IndexTimes times =
        lod::indexChunks(chunks, counts, load, grid, s.params, assembler, window, s.run);
    s.phases.push_back(times.index);
    s.phases.back().bytes = spill.bytesWritten();
    s.phases.push_back(lod::writePhase(times, n));
    report.octree = assembler.stats();
    report.spillBytes = spill.bytesWritten();
  }
  report.seconds = since(s.start);
  report.tailBytes = s.params.tailBytes;
  report.phases = s.phases;
  report.metadata = s.metadata;
  report.metadata.depth = report.octree.levels - 1;
  return report;
}

} // namespace pointrast::io
