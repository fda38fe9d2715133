// pointrast bench-io FILE...: LAZ decoding and encoding throughput, 1 and N threads (bench/io_bench.h).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <unistd.h>

#include "base/error.h"
#include "base/parallel.h"
#include "bench/io_bench.h"
#include "bench/report.h"
#include "bench/report_parts.h"
#include "cli_util.h"
#include "commands.h"
#include "io/io_util.h"

namespace pointrast::app {

namespace {

struct BenchIoArgs {
  std::vector<std::string> inputs;
  std::string points = "0";
  std::vector<std::string> threads;
  std::vector<int> pointFormats;
  std::string disk = "0", diskDir = ".";
  int repeats = 5;
  bool noReadCloud = false, noEncode = false, json = false, quiet = false;
  std::string out, name = "io-laz";
};

std::vector<unsigned> parseThreads(const std::vector<std::string>& items) {
  std::vector<unsigned> threads;
  for (const std::string& item : items) {
    if (item == "all") {
      threads.push_back(hardwareThreads());
      continue;
    }
    const uint64_t n = parseCount(item, "--threads");
    if (n < 1 || n > 4096) throw InputError("--threads: " + item + " is not a thread count (1..4096 or all)");
    threads.push_back(unsigned(n));
  }
  return threads;
}

void writeFile(const std::filesystem::path& path, const std::string& text) {
  io::detail::PartialFile file(path);
  file.write(text.data(), text.size());
  file.commit();
}

int runBenchIo(const BenchIoArgs& a) {
  bench::IoBenchConfig config;
  for (const std::string& input : a.inputs)
    config.inputs.emplace_back(input);
  config.minPoints = parseCount(a.points, "--points");
  config.threads = parseThreads(a.threads);
  if (a.repeats < 1 || a.repeats > 1000) throw InputError("--repeats must be 1 to 1000");
  config.repeats = a.repeats;
  config.readCloud = !a.noReadCloud;
  config.encode = !a.noEncode;
  for (int format : a.pointFormats)
    if (!(format >= 0 && format <= 3) && !(format >= 6 && format <= 8))
      throw InputError("--point-formats: " + std::to_string(format) +
                       " is not a point format LAZ is written in (0-3, 6-8)");
  config.pointFormats = a.pointFormats;
  config.diskBytes = parseBytes(a.disk, "--disk");
  config.diskDir = a.diskDir;
  if (config.diskBytes && !std::filesystem::is_directory(config.diskDir))
    throw InputError("--disk-dir: " + a.diskDir + " is not a folder");
  config.workDir =
      std::filesystem::temp_directory_path() / ("pointrast-bench-io-" + std::to_string(::getpid()));
  struct Cleanup {
    std::filesystem::path dir;
    ~Cleanup() {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    }
  } cleanup{config.workDir};

  const bench::IoBenchRun run = bench::runIoBench(config, !a.quiet);
  const std::string date = bench::utcNow();
  const std::string command = commandLine("pointrast bench-io");
  const nlohmann::json j = bench::ioRunJson(run, command, date);
  const std::filesystem::path dir = a.out.empty()
                                        ? std::filesystem::path("bench/results") / bench::ioDeviceName(run)
                                        : std::filesystem::path(a.out);
  std::filesystem::create_directories(dir);
  writeFile(dir / (a.name + ".json"), bench::jsonFileText(j));
  writeFile(dir / (a.name + ".md"), bench::ioMarkdownReport(run, command, date));
  if (a.json) std::printf("%s\n", jsonText(j).c_str());
  if (!a.quiet)
    std::fprintf(a.json ? stderr : stdout, "%zu file%s in %.1f s; wrote %s and %s\n", run.results.size(),
                 run.results.size() == 1 ? "" : "s", run.seconds, (dir / (a.name + ".json")).string().c_str(),
                 (dir / (a.name + ".md")).string().c_str());
  return 0;
}

} // namespace

Command addBenchIo(CLI::App& app) {
  auto a = std::make_shared<BenchIoArgs>();
  CLI::App* cmd =
      app.add_subcommand("bench-io", "Measure LAZ decoding and encoding throughput on 1 and on all cores");
  cmd->footer(
      "\nDecodes every chunk of each LAZ (or COPC) file to raw LAS records, from compressed chunks read\n"
      "into memory first, once per thread count and --repeats times; reports the median and best\n"
      "wall time, points/s, points/s per thread and points per CPU-second (from each thread's CPU\n"
      "clock: what a core delivers on a shared machine; the load average is recorded). Then encodes\n"
      "the same records, decoded once into memory, back to LAZ chunks of the file's point format\n"
      "(0-3, 6-8) with pointrast's encoder at the same thread counts, and times readCloud end to end.\n"
      "--points replicates a file's own chunks (chunks decode on their own)\n"
      "into a temporary LAZ of at least that many points. --point-formats first converts each file to\n"
      "those point formats (pointrast's LAZ encoder) and times each. --disk SIZE also measures the\n"
      "sequential write bandwidth of the folder --disk-dir (a file of SIZE, timed until fdatasync\n"
      "returns, once plain and once with the octree writer's write-behind). Writes <name>.json and\n"
      "<name>.md to bench/results/cpu-<model>-<threads>t/.\n"
      "Examples:\n  pointrast bench-io autzen_trim.laz --points 3M\n"
      "  pointrast bench-io autzen_trim.laz --points 30M --point-formats 3,7 --disk 8G --disk-dir out/\n"
      "  pointrast bench-io a.laz b.laz --points 3M --threads 1,4,all --repeats 9");
  cmd->add_option("FILE", a->inputs, "LAZ or COPC files")->required();
  cmd->add_option("--points", a->points,
                  "Replicate each file's chunks to at least this many points (3M, 1.5G)");
  cmd->add_option("--threads", a->threads, "Thread counts to time (default: 1,all)")->delimiter(',');
  cmd->add_option("--point-formats", a->pointFormats, "Convert each file to these point formats first (3,7)")
      ->delimiter(',');
  cmd->add_option("--disk", a->disk, "Also measure sequential write bandwidth with a file of this size (4G)");
  cmd->add_option("--disk-dir", a->diskDir, "Folder for the disk measurement")->capture_default_str();
  cmd->add_option("--repeats", a->repeats, "Timed runs per thread count")->capture_default_str();
  cmd->add_flag("--no-read-cloud", a->noReadCloud, "Skip the readCloud timing");
  cmd->add_flag("--no-encode", a->noEncode, "Skip the encoding timing");
  cmd->add_option("--out", a->out, "Folder for the reports (default: bench/results/cpu-<model>-<threads>t/)");
  cmd->add_option("--name", a->name, "Report file stem")->capture_default_str();
  cmd->add_flag("--json", a->json, "Print the report's JSON on stdout");
  cmd->add_flag("--quiet", a->quiet, "No progress lines");
  return [a] { return runBenchIo(*a); };
}

} // namespace pointrast::app
