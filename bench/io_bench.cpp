#include "bench/io_bench.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <optional>
#include <sstream>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include "base/build_info.h"
#include "base/parallel.h"
#include "bench/report.h"
#include "io/io_util.h"
#include "io/las/laz_chunk.h"
#include "io/las/laz_compose.h"
#include "io/las/laz_encoder.h"
#include "io/las/laz_reader.h"
#include "io/write_behind.h"
#include "io/writer.h"

namespace pointrast::bench {

namespace {

using Clock = std::chrono::steady_clock;

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

std::string firstLine(const char* path, const char* key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (!key || line.rfind(key, 0) == 0) {
      if (key) {
        const size_t colon = line.find(':');
        return colon == std::string::npos ? line : line.substr(line.find_first_not_of(" \t", colon + 1));
      }
      return line;
    }
  return "";
}

// The compressed chunks of a file, in memory.
struct LoadedLaz {
  io::laz::LazFile laz;
  std::vector<std::vector<uint8_t>> chunks;
  uint64_t points = 0, bytes = 0;
};

LoadedLaz load(const std::filesystem::path& path) {
  io::detail::InputFile file(path);
  LoadedLaz l;
  l.laz = io::laz::openLaz(file);
  for (const io::laz::Chunk& c : l.laz.chunks) {
    l.chunks.emplace_back(c.bytes);
    file.readAt(c.offset, l.chunks.back().data(), c.bytes);
    l.points += c.pointCount;
    l.bytes += c.bytes;
  }
  return l;
}

struct OneRun {
  double wall = 0, cpu = 0;
};

// What one thread keeps from run to run, made on that thread during the warm-up: its coder's models and
// its output buffer come from its own malloc arena (and its own NUMA node), no timed run allocates or
// faults in pages, and slots are cache-line aligned so that threads share no line they write.
struct alignas(64) DecodeSlot {
  std::unique_ptr<io::laz::ChunkDecoder> decoder;
  std::vector<uint8_t> records;
  double cpu = 0;
};

struct alignas(64) EncodeSlot {
  std::unique_ptr<io::laz::ChunkEncoder> encoder;
  uint64_t bytes = 0;
  double cpu = 0;
};

// Runs task(slot, i) for i in [0, tasks) on slots.size() threads (thread 0 the calling one), each task
// to whichever thread asks next, and times the whole.
template <class Slot, class Task>
OneRun runOnThreads(std::vector<Slot>& slots, size_t tasks, const Task& task) {
  struct alignas(64) Counter {
    std::atomic<size_t> next{0};
  } counter;
  auto work = [&](unsigned t) {
    Slot& slot = slots[t];
    const double c0 = threadCpuSeconds();
    for (size_t i = counter.next.fetch_add(1, std::memory_order_relaxed); i < tasks;
         i = counter.next.fetch_add(1, std::memory_order_relaxed))
      task(slot, i);
    slot.cpu = threadCpuSeconds() - c0;
  };
  const Clock::time_point start = Clock::now();
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < slots.size(); ++t)
    pool.emplace_back(work, t);
  work(0);
  for (std::thread& t : pool)
    t.join();
  OneRun r;
  r.wall = std::chrono::duration<double>(Clock::now() - start).count();
  for (const Slot& slot : slots)
    r.cpu += slot.cpu;
  return r;
}

// Every chunk decoded once, chunks handed out in file order.
OneRun decodeOnce(const LoadedLaz& l, std::vector<DecodeSlot>& slots) {
  return runOnThreads(slots, l.chunks.size(), [&](DecodeSlot& slot, size_t i) {
    if (!slot.decoder) slot.decoder = std::make_unique<io::laz::ChunkDecoder>(l.laz.layout);
    slot.decoder->decode(l.chunks[i].data(), l.chunks[i].size(), l.laz.chunks[i].pointCount, slot.records);
  });
}

// The raw records of a file's distinct chunks (a replicated file repeats them), decoded once: what the
// encoder is timed on.
struct DecodedChunks {
  std::vector<std::vector<uint8_t>> records;
  std::vector<uint64_t> counts;
};

DecodedChunks decodeDistinct(const LoadedLaz& l, uint64_t copies) {
  DecodedChunks d;
  const size_t distinct = std::max<size_t>(1, l.chunks.size() / std::max<uint64_t>(1, copies));
  io::laz::ChunkDecoder decoder(l.laz.layout);
  for (size_t i = 0; i < distinct && i < l.chunks.size(); ++i) {
    d.records.emplace_back();
    decoder.decode(l.chunks[i].data(), l.chunks[i].size(), l.laz.chunks[i].pointCount, d.records.back());
    d.counts.push_back(l.laz.chunks[i].pointCount);
  }
  return d;
}

// Every chunk of the file (`chunks` of them, cycling through the distinct ones) encoded once; `bytes`
// receives the compressed size of the run.
OneRun encodeOnce(const DecodedChunks& d, size_t chunks, const io::laz::Layout& layout,
                  std::vector<EncodeSlot>& slots, uint64_t& bytes) {
  for (EncodeSlot& slot : slots)
    slot.bytes = 0;
  const OneRun r = runOnThreads(slots, chunks, [&](EncodeSlot& slot, size_t i) {
    const size_t c = i % d.records.size();
    if (d.counts[c] == 0) return;
    if (!slot.encoder) slot.encoder = std::make_unique<io::laz::ChunkEncoder>(layout);
    slot.bytes += slot.encoder->encode(d.records[c].data(), d.counts[c]).size();
  });
  bytes = 0;
  for (const EncodeSlot& slot : slots)
    bytes += slot.bytes;
  return r;
}

IoTiming summarize(std::vector<OneRun> runs, unsigned threads, uint64_t points) {
  std::sort(runs.begin(), runs.end(), [](const OneRun& a, const OneRun& b) { return a.wall < b.wall; });
  IoTiming t;
  t.threads = threads;
  t.points = points;
  t.bestSeconds = runs.front().wall;
  t.medianSeconds = runs[runs.size() / 2].wall;
  t.cpuSeconds = runs[runs.size() / 2].cpu;
  return t;
}

std::string layoutText(const io::laz::LazFile& laz) {
  const io::detail::LasHeader& hd = laz.header;
  return io::detail::strFormat("LAZ %d.%d point format %d: %s (%s)", hd.versionMajor, hd.versionMinor,
                               hd.pointFormat, laz.layout.describeItems().c_str(),
                               laz.layout.describeCompressor().c_str());
}

[[noreturn]] void failDisk(const std::filesystem::path& path, int error, const char* what) {
  io::detail::fail(path, io::detail::strFormat("%s: %s", what, std::strerror(error)));
}

double mega(double v) {
  return v / 1e6;
}

} // namespace

DiskTiming measureDiskWrite(const std::filesystem::path& dir, uint64_t bytes, bool writeBehind) {
  const std::filesystem::path path = dir / (".pointrast-disk-" + std::to_string(::getpid()));
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) failDisk(path, errno, "cannot create a file to measure the disk");
  struct Remove {
    int fd;
    std::filesystem::path path;
    ~Remove() {
      ::close(fd);
      std::error_code ec;
      std::filesystem::remove(path, ec);
    }
  } remove{fd, path};
  // Bytes that no file system compresses or deduplicates.
  std::vector<uint8_t> block(size_t(8) << 20);
  uint64_t x = 0x9E3779B97F4A7C15ull;
  for (size_t i = 0; i + 8 <= block.size(); i += 8) {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    std::memcpy(block.data() + i, &x, 8);
  }
  DiskTiming t;
  t.mode = writeBehind ? "write-behind" : "plain";
  const Clock::time_point start = Clock::now();
  {
    std::optional<io::detail::WriteBehind> behind;
    if (writeBehind) behind.emplace(fd);
    for (uint64_t done = 0; done < bytes;) {
      const size_t n = size_t(std::min<uint64_t>(block.size(), bytes - done));
      const ssize_t w = ::pwrite(fd, block.data(), n, off_t(done));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) failDisk(path, w < 0 ? errno : EIO, "cannot write");
      if (behind) behind->written(done, uint64_t(w));
      done += uint64_t(w);
    }
    if (behind && behind->finish() != 0) failDisk(path, EIO, "cannot write");
  }
  if (::fdatasync(fd) != 0) failDisk(path, errno, "cannot sync");
  t.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  t.bytes = bytes;
  return t;
}

double IoTiming::pointsPerSecond() const {
  return medianSeconds > 0 ? double(points) / medianSeconds : 0;
}
double IoTiming::pointsPerSecondPerThread() const {
  return threads ? pointsPerSecond() / threads : 0;
}
double IoTiming::pointsPerCpuSecond() const {
  return cpuSeconds > 0 ? double(points) / cpuSeconds : 0;
}

IoBenchRun runIoBench(const IoBenchConfig& config, bool progress) {
  const Clock::time_point begin = Clock::now();
  IoBenchRun run;
  run.cpu = firstLine("/proc/cpuinfo", "model name");
  run.hardwareThreads = hardwareThreads();
  run.loadBefore = firstLine("/proc/loadavg", nullptr);
  std::vector<unsigned> threadCounts = config.threads;
  if (threadCounts.empty()) threadCounts = {1, run.hardwareThreads};
  std::sort(threadCounts.begin(), threadCounts.end());
  threadCounts.erase(std::unique(threadCounts.begin(), threadCounts.end()), threadCounts.end());

  auto benchFile = [&](const std::filesystem::path& input, const std::string& name) {
    IoResult result;
    result.file = name;
    std::filesystem::path path = input;
    {
      io::detail::InputFile file(input);
      const io::laz::LazFile laz = io::laz::openLaz(file);
      const uint64_t points = laz.header.pointCount;
      if (config.minPoints > points && points > 0) {
        // Chunks decode on their own: the file's chunks, repeated, with a rebuilt table, are a valid LAZ.
        result.copies = (config.minPoints + points - 1) / points;
        std::vector<size_t> picks;
        for (uint64_t c = 0; c < result.copies; ++c)
          for (size_t i = 0; i < laz.chunks.size(); ++i)
            picks.push_back(i);
        std::filesystem::create_directories(config.workDir);
        path = config.workDir / (input.stem().string() + "-x" + std::to_string(result.copies) + ".laz");
        io::writeComposedLaz(input, picks, path);
      }
    }
    const LoadedLaz loaded = load(path);
    result.layout = layoutText(loaded.laz);
    result.points = loaded.points;
    result.chunks = loaded.chunks.size();
    result.compressedBytes = loaded.bytes;
    for (unsigned threads : threadCounts) {
      std::vector<DecodeSlot> slots(threads);
      decodeOnce(loaded, slots); // warm-up: each thread makes its decoder and buffer, caches fill
      std::vector<OneRun> runs;
      for (int r = 0; r < std::max(1, config.repeats); ++r)
        runs.push_back(decodeOnce(loaded, slots));
      result.decode.push_back(summarize(runs, threads, loaded.points));
      const IoTiming& t = result.decode.back();
      if (progress)
        std::fprintf(
            stderr, "%s: %u thread%s: %.1f M points/s (%.2f M/s per thread, %.2f M per CPU-second)\n",
            path.filename().string().c_str(), threads, threads == 1 ? "" : "s", mega(t.pointsPerSecond()),
            mega(t.pointsPerSecondPerThread()), mega(t.pointsPerCpuSecond()));
    }
    const int format = loaded.laz.header.pointFormat;
    if (config.encode && io::laz::canEncodePointFormat(format) && !loaded.chunks.empty()) {
      const DecodedChunks records = decodeDistinct(loaded, result.copies);
      const io::laz::Layout layout =
          io::laz::encoderLayout(format, loaded.laz.layout.recordLength, loaded.laz.layout.chunkSize);
      for (unsigned threads : threadCounts) {
        std::vector<EncodeSlot> slots(threads);
        encodeOnce(records, loaded.chunks.size(), layout, slots, result.encodedBytes); // warm-up
        std::vector<OneRun> runs;
        for (int r = 0; r < std::max(1, config.repeats); ++r)
          runs.push_back(encodeOnce(records, loaded.chunks.size(), layout, slots, result.encodedBytes));
        result.encode.push_back(summarize(runs, threads, loaded.points));
        const IoTiming& t = result.encode.back();
        if (progress)
          std::fprintf(stderr,
                       "%s: encoding, %u thread%s: %.1f M points/s (%.2f M/s per thread, %.2f M per "
                       "CPU-second)\n",
                       path.filename().string().c_str(), threads, threads == 1 ? "" : "s",
                       mega(t.pointsPerSecond()), mega(t.pointsPerSecondPerThread()),
                       mega(t.pointsPerCpuSecond()));
      }
    }
    if (config.readCloud) {
      const unsigned threads = threadCounts.back();
      io::detail::setLazThreads(threads);
      io::ReadOptions options;
      options.progress = false;
      std::vector<OneRun> runs;
      for (int r = 0; r < std::max(1, config.repeats); ++r) {
        const Clock::time_point start = Clock::now();
        const PointCloud cloud = io::readCloud(path, options);
        runs.push_back({std::chrono::duration<double>(Clock::now() - start).count(), 0});
      }
      io::detail::setLazThreads(0);
      result.readCloud = summarize(runs, threads, loaded.points);
    }
    if (path != input) std::filesystem::remove(path);
    run.results.push_back(std::move(result));
  };
  for (const std::filesystem::path& input : config.inputs) {
    if (config.pointFormats.empty()) {
      benchFile(input, input.filename().string());
      continue;
    }
    // The same points in other point formats, coded by pointrast's LAZ encoder: every conversion first,
    // so that a format the points cannot take (colors into point format 6) stops the run before anything
    // is timed.
    std::filesystem::create_directories(config.workDir);
    std::vector<std::pair<std::filesystem::path, std::string>> converted;
    try {
      for (int format : config.pointFormats) {
        const std::string name = input.stem().string() + "-pf" + std::to_string(format) + ".laz";
        converted.emplace_back(config.workDir / name, name);
        io::LasConvertOptions options;
        options.pointFormat = format;
        io::convertLasFile(input, converted.back().first, options);
      }
      for (const auto& [path, name] : converted) {
        benchFile(path, name);
        std::filesystem::remove(path);
      }
    } catch (...) {
      std::error_code ignored;
      for (const auto& entry : converted)
        std::filesystem::remove(entry.first, ignored);
      throw;
    }
  }
  if (config.diskBytes) {
    run.diskDir = config.diskDir.string();
    for (const bool writeBehind : {false, true}) {
      run.disk.push_back(measureDiskWrite(config.diskDir, config.diskBytes, writeBehind));
      if (progress)
        std::fprintf(stderr, "disk %s: %s: %.0f MB/s\n", run.diskDir.c_str(), run.disk.back().mode.c_str(),
                     run.disk.back().bytesPerSecond() / 1e6);
    }
  }
  run.loadAfter = firstLine("/proc/loadavg", nullptr);
  run.seconds = std::chrono::duration<double>(Clock::now() - begin).count();
  return run;
}

std::string ioDeviceName(const IoBenchRun& run) {
  return "cpu-" + sanitizeName(run.cpu) + "-" + std::to_string(run.hardwareThreads) + "t";
}

nlohmann::json ioRunJson(const IoBenchRun& run, const std::string& commandLine, const std::string& date) {
  nlohmann::json j;
  j["suite"] = "io";
  j["cpu"] = run.cpu;
  j["hardware_threads"] = run.hardwareThreads;
  j["load_average_before"] = run.loadBefore;
  j["load_average_after"] = run.loadAfter;
  j["command"] = commandLine;
  j["date"] = date;
  j["commit"] = buildCommit();
  j["seconds"] = run.seconds;
  j["results"] = nlohmann::json::array();
  for (const IoResult& r : run.results) {
    nlohmann::json jr = {{"file", r.file},
                         {"layout", r.layout},
                         {"points", r.points},
                         {"copies", r.copies},
                         {"chunks", r.chunks},
                         {"compressed_bytes", r.compressedBytes},
                         {"decode", nlohmann::json::array()}};
    auto timing = [](const IoTiming& t) {
      return nlohmann::json{{"threads", t.threads},
                            {"median_s", t.medianSeconds},
                            {"best_s", t.bestSeconds},
                            {"cpu_s", t.cpuSeconds},
                            {"points_per_s", t.pointsPerSecond()},
                            {"points_per_s_per_thread", t.pointsPerSecondPerThread()},
                            {"points_per_cpu_s", t.pointsPerCpuSecond()}};
    };
    for (const IoTiming& t : r.decode)
      jr["decode"].push_back(timing(t));
    if (!r.encode.empty()) {
      jr["encode"] = nlohmann::json::array();
      for (const IoTiming& t : r.encode)
        jr["encode"].push_back(timing(t));
      jr["encoded_bytes"] = r.encodedBytes;
    }
    if (r.readCloud.threads) jr["read_cloud"] = timing(r.readCloud);
    j["results"].push_back(jr);
  }
  if (!run.disk.empty()) {
    j["disk_write"] = {{"dir", run.diskDir}, {"runs", nlohmann::json::array()}};
    for (const DiskTiming& d : run.disk)
      j["disk_write"]["runs"].push_back({{"mode", d.mode},
                                         {"bytes", d.bytes},
                                         {"seconds", d.seconds},
                                         {"bytes_per_s", d.bytesPerSecond()}});
  }
  return j;
}

std::string ioMarkdownReport(const IoBenchRun& run, const std::string& commandLine, const std::string& date) {
  std::ostringstream md;
  md << "# LAZ decoding and encoding throughput\n\n";
  md << "CPU: " << run.cpu << ", " << run.hardwareThreads
     << " hardware threads. Load average before: " << run.loadBefore << "; after: " << run.loadAfter
     << ".\n\n";
  md << "Decoding to raw LAS records from compressed chunks in memory; each row the median of the runs (best "
        "in "
        "parentheses). Per CPU-second: points over the decoding threads' CPU time, what one core delivers "
        "whatever else the machine runs.\n\n";
  md << "| file | points | threads | median s (best) | M points/s | M points/s per thread | M points per "
        "CPU-s |\n";
  md << "| --- | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  char line[512];
  for (const IoResult& r : run.results) {
    for (const IoTiming& t : r.decode) {
      std::snprintf(line, sizeof line, "| %s | %llu | %u | %.3f (%.3f) | %.2f | %.2f | %.2f |\n",
                    r.file.c_str(), static_cast<unsigned long long>(r.points), t.threads, t.medianSeconds,
                    t.bestSeconds, mega(t.pointsPerSecond()), mega(t.pointsPerSecondPerThread()),
                    mega(t.pointsPerCpuSecond()));
      md << line;
    }
  }
  bool encoded = false;
  for (const IoResult& r : run.results)
    encoded = encoded || !r.encode.empty();
  if (encoded) {
    md << "\nEncoding the same raw LAS records (decoded once, in memory) to LAZ chunks of the file's point "
          "format and chunk size with pointrast's encoder:\n\n";
    md << "| file | points | threads | median s (best) | M points/s | M points/s per thread | M points per "
          "CPU-s | B per point |\n";
    md << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    for (const IoResult& r : run.results)
      for (const IoTiming& t : r.encode) {
        std::snprintf(line, sizeof line, "| %s | %llu | %u | %.3f (%.3f) | %.2f | %.2f | %.2f | %.2f |\n",
                      r.file.c_str(), static_cast<unsigned long long>(r.points), t.threads, t.medianSeconds,
                      t.bestSeconds, mega(t.pointsPerSecond()), mega(t.pointsPerSecondPerThread()),
                      mega(t.pointsPerCpuSecond()),
                      r.points ? double(r.encodedBytes) / double(r.points) : 0.0);
        md << line;
      }
  }
  md << "\nreadCloud (records into the renderer's cloud, all stages) at the highest thread count:\n\n";
  md << "| file | threads | median s (best) | M points/s |\n| --- | ---: | ---: | ---: |\n";
  for (const IoResult& r : run.results)
    if (r.readCloud.threads) {
      std::snprintf(line, sizeof line, "| %s | %u | %.3f (%.3f) | %.2f |\n", r.file.c_str(),
                    r.readCloud.threads, r.readCloud.medianSeconds, r.readCloud.bestSeconds,
                    mega(r.readCloud.pointsPerSecond()));
      md << line;
    }
  if (!run.disk.empty()) {
    md << "\nSequential write of one new file in `" << run.diskDir
       << "` (8 MiB writes, timed until fdatasync returns):\n\n";
    md << "| mode | MB | s | MB/s |\n| --- | ---: | ---: | ---: |\n";
    for (const DiskTiming& d : run.disk) {
      std::snprintf(line, sizeof line, "| %s | %.0f | %.3f | %.0f |\n", d.mode.c_str(), double(d.bytes) / 1e6,
                    d.seconds, d.bytesPerSecond() / 1e6);
      md << line;
    }
  }
  md << "\nFiles:\n\n";
  for (const IoResult& r : run.results) {
    std::snprintf(line, sizeof line, "- %s x %llu: %s, %llu chunks, %.1f MB compressed (%.2f B per point)\n",
                  r.file.c_str(), static_cast<unsigned long long>(r.copies), r.layout.c_str(),
                  static_cast<unsigned long long>(r.chunks), double(r.compressedBytes) / 1e6,
                  r.points ? double(r.compressedBytes) / double(r.points) : 0.0);
    md << line;
  }
  md << "\nCommand: `" << commandLine << "`, " << date << ", " << run.seconds << " s; pointrast "
     << buildCommit() << ".\n";
  return md.str();
}

} // namespace pointrast::bench
