// LAZ decoding and encoding throughput (`pointrast bench-io`): a LAZ file, replicated from its own chunks
// to a target point count when asked, decoded to raw LAS records with one thread and with N threads, its
// compressed chunks read into memory first so the figures are the decoder's, not the disk's; then the
// same records (decoded once, in memory) encoded back to LAZ chunks of the file's point format. Each
// configuration is timed `repeats` times; the report gives the median and the best, wall-clock points/s
// and, from each thread's CPU clock, points per CPU-second (what a core delivers when the machine is
// shared, as the load average written beside the figures tells).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pointrast::bench {

struct IoBenchConfig {
  std::vector<std::filesystem::path> inputs; // LAZ or COPC files
  uint64_t minPoints = 0;                    // replicate chunks until at least this many points (0: as is)
  std::vector<unsigned> threads;             // thread counts to time (1 and all hardware threads by default)
  int repeats = 5;
  bool readCloud = true; // also time readCloud (records into a PointCloud) at the highest thread count
  bool encode = true;    // also time the encoder (point formats 0-3 and 6-8) at every thread count
  std::filesystem::path workDir; // where replicated files go (removed after the run)
  // Each input converted to these point formats (0-3, 6-8) and timed in each; empty: as it is.
  std::vector<int> pointFormats;
  uint64_t diskBytes = 0;        // sequential write bandwidth measured with a file this large (0: not)
  std::filesystem::path diskDir; // where that file is written (and removed)
};

// Sequential write of one new file in 8 MiB pwrites, timed until fdatasync returns: once as plain
// writes, once with the octree writer's write-behind (io/write_behind.h).
struct DiskTiming {
  std::string mode; // "plain" or "write-behind"
  uint64_t bytes = 0;
  double seconds = 0;
  double bytesPerSecond() const { return seconds > 0 ? double(bytes) / seconds : 0; }
};

struct IoTiming {
  unsigned threads = 0;
  double medianSeconds = 0, bestSeconds = 0;
  double cpuSeconds = 0; // summed over the threads, of the median run
  double pointsPerSecond() const;
  double pointsPerSecondPerThread() const;
  double pointsPerCpuSecond() const;
  uint64_t points = 0;
};

struct IoResult {
  std::string file;    // the input's name
  std::string layout;  // "LAZ 1.2 point format 3: POINT10 v2, GPSTIME11 v2, RGB12 v2 (pointwise chunks)"
  uint64_t points = 0; // decoded per run
  uint64_t copies = 1; // of the input's chunks
  uint64_t chunks = 0;
  uint64_t compressedBytes = 0;
  std::vector<IoTiming> decode; // per thread count
  std::vector<IoTiming> encode; // per thread count; empty: not timed
  uint64_t encodedBytes = 0;    // the chunks the encoder wrote in one run
  IoTiming readCloud;           // threads == 0: not timed
};

struct IoBenchRun {
  std::vector<IoResult> results;
  std::string diskDir;          // where the disk was measured
  std::vector<DiskTiming> disk; // empty: not measured
  std::string cpu;              // model name
  unsigned hardwareThreads = 0;
  std::string loadBefore, loadAfter; // /proc/loadavg
  double seconds = 0;
};

IoBenchRun runIoBench(const IoBenchConfig& config, bool progress);

// Writes `bytes` to a new file in `dir` and removes it (InputError when it cannot be written).
DiskTiming measureDiskWrite(const std::filesystem::path& dir, uint64_t bytes, bool writeBehind);

// "cpu-amd-epyc-2t": the results folder name of this machine.
std::string ioDeviceName(const IoBenchRun& run);
nlohmann::json ioRunJson(const IoBenchRun& run, const std::string& commandLine, const std::string& date);
std::string ioMarkdownReport(const IoBenchRun& run, const std::string& commandLine, const std::string& date);

} // namespace pointrast::bench
