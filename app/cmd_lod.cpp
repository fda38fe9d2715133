// pointrast lod IN... -o DIR: a level-of-detail octree (Potree 2.0) from point files.
#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "base/error.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "cli_util.h"
#include "commands.h"
#include "gpu/context.h"
#include "io/copc_ept/copc_writer.h"
#include "io/format_table.h"
#include "io/output_check.h"
#include "io/potree/lod_potree.h"
#include "io/writer.h"
#include "render/gpu_indexer.h"

namespace pointrast::app {

namespace {

struct LodArgs {
  std::vector<std::string> inputs;
  std::string output, memory, leafPoints = "20k", encoding = "default", colorFilter = "average";
  std::string format; // potree or copc; empty: by the output's name (".laz": copc)
  std::string indexOn = "cpu";
  double spacing = 0;
  unsigned threads = 0;
  bool noColorFilter = false;
  bool json = false, quiet = false;
};

// Ctrl-C, a termination request, a closed terminal (SIGHUP) or a closed pipe (SIGPIPE) asks the build to
// stop: it unwinds, and the writer removes its temporary folder with the chunk files in it. The handler
// only sets a flag (all a signal handler may do); SA_RESETHAND makes a second Ctrl-C end the process at
// once, for a user who will not wait: what that leaves, the next build of the same folder removes.
std::atomic<bool> gInterrupted{false};
extern "C" void onInterrupt(int) {
  gInterrupted.store(true);
}

class InterruptGuard {
public:
  InterruptGuard() {
    struct sigaction action {};
    action.sa_handler = onInterrupt;
    action.sa_flags = SA_RESETHAND;
    sigemptyset(&action.sa_mask);
    for (size_t i = 0; i < kSignals.size(); ++i)
      sigaction(kSignals[i], &action, &old_[i]);
  }
  ~InterruptGuard() {
    for (size_t i = 0; i < kSignals.size(); ++i)
      sigaction(kSignals[i], &old_[i], nullptr);
  }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

private:
  static constexpr std::array<int, 4> kSignals{SIGINT, SIGTERM, SIGHUP, SIGPIPE};
  std::array<struct sigaction, 4> old_{};
};

// The octree's folder is new, in a folder that exists and may be written to: said before any point is read.
void checkOutputFolder(std::string& output) {
  if (output.empty()) throw InputError("-o: give the name of a new folder for the octree");
  while (output.size() > 1 && output.back() == '/') // "new/" names the folder "new"
    output.pop_back();
  std::error_code ec;
  if (std::filesystem::exists(std::filesystem::symlink_status(output, ec)))
    throw InputError(output + ": already exists (an octree is written into a new folder)");
  io::checkOutputTarget(output, "-o");
}

double perSecond(double count, double seconds) {
  return seconds > 0 ? count / seconds : 0;
}

// Where the index phase ran: the device and how many chunks it took (the CPU takes the ones it cannot).
struct IndexDevice {
  std::string name;
  render::GpuIndexer::Stats stats;
};

nlohmann::json toJson(const LodArgs& a, const io::PotreeBuildReport& r, const IndexDevice* device) {
  const io::LodBuildReport& b = r.build;
  nlohmann::json j;
  j["command"] = "lod";
  j["inputs"] = a.inputs;
  j["output"] = a.output;
  j["points"] = b.octree.points;
  j["nodes"] = b.octree.nodes;
  j["levels"] = b.octree.levels;
  j["bytes"] = r.bytes;
  j["input_bytes"] = b.inputBytes;
  j["seconds"] = b.seconds;
  j["points_per_second"] = perSecond(double(b.octree.points), b.seconds);
  j["threads"] = b.threads;
  j["memory_bytes"] = b.memoryBytes;
  j["out_of_core"] = b.outOfCore;
  j["spill_bytes"] = b.spillBytes;
  j["chunks"] = b.chunks;
  j["spacing"] = b.metadata.spacing;
  j["format"] = a.format;
  j["encoding"] = a.encoding;
  j["color_filter"] = a.colorFilter;
  j["index_on"] = a.indexOn;
  if (device) {
    j["index_device"] = device->name;
    j["index_gpu_chunks"] = device->stats.gpuChunks;
    j["index_cpu_chunks"] = device->stats.cpuChunks;
    j["index_device_seconds"] = device->stats.deviceSeconds;
    const render::GpuIndexer::Stats& st = device->stats;
    j["index_device_steps"] = {{"stage", st.stageSeconds},
                               {"sort", st.sortSeconds},
                               {"order", st.orderSeconds},
                               {"levels", st.levelSeconds},
                               {"read", st.readSeconds}};
    j["index_wait_seconds"] = st.waitSeconds;
    j["index_device_busy_seconds"] = st.busySeconds;
  }
  nlohmann::json phases = nlohmann::json::array();
  for (const lod::LodPhase& p : b.phases) {
    nlohmann::json q;
    q["name"] = p.name;
    q["seconds"] = p.seconds;
    q["cpu_seconds"] = p.cpuSeconds;
    q["points_per_second"] = perSecond(double(p.points), p.seconds);
    q["bytes"] = p.bytes;
    q["overlapped"] = p.overlapped;
    if (p.overlapped) q["thread_seconds"] = p.threadSeconds;
    phases.push_back(q);
  }
  j["phases"] = phases;
  return j;
}

void printSummary(const LodArgs& a, const io::PotreeBuildReport& r, const IndexDevice* device) {
  const io::LodBuildReport& b = r.build;
  std::printf("%s: %s points in %s nodes, %d levels, %.1f MB, in %.2f s (%s points/s; %s, %u threads)\n",
              a.output.c_str(), humanCount(double(b.octree.points)).c_str(),
              humanCount(double(b.octree.nodes)).c_str(), b.octree.levels, double(r.bytes) / 1e6, b.seconds,
              humanCount(perSecond(double(b.octree.points), b.seconds)).c_str(),
              b.outOfCore ? "out of core" : "in memory", b.threads);
  for (const lod::LodPhase& p : b.phases) {
    std::printf("  %-10s %8.3f s %10s points/s", p.name.c_str(), p.seconds,
                humanCount(perSecond(double(p.points), p.seconds)).c_str());
    if (p.overlapped && p.bytes && &p != &b.phases.front())
      std::printf("   (during index; %.3f s over all threads; %.1f MB, %.0f MB/s of index's time)\n",
                  p.threadSeconds, double(p.bytes) / 1e6,
                  perSecond(double(p.bytes), (&p - 1)->seconds) / 1e6);
    else if (p.overlapped)
      std::printf("   (during index; %.3f s over all threads)\n", p.threadSeconds);
    else
      std::printf("   cpu %7.3f s\n", p.cpuSeconds);
  }
  if (device)
    std::printf("  index on %s: %llu chunks (%llu on the CPU), %.3f s of device work\n", device->name.c_str(),
                static_cast<unsigned long long>(device->stats.gpuChunks),
                static_cast<unsigned long long>(device->stats.cpuChunks), device->stats.deviceSeconds);
}

int runLod(LodArgs a) {
  io::LodBuildOptions options;
  options.spacing = a.spacing;
  options.leafPoints = parseCount(a.leafPoints, "--leaf-points");
  if (options.leafPoints < 1) throw InputError("--leaf-points expects at least 1");
  if (!a.memory.empty()) options.memoryBytes = parseBytes(a.memory, "--memory");
  options.threads = a.threads;
  options.progress = !a.quiet && !a.json;
  if (a.colorFilter != "average" && a.colorFilter != "none")
    throw InputError("--color-filter expects average or none, got '" + a.colorFilter + "'");
  if (a.noColorFilter) a.colorFilter = "none";
  options.averageColors = a.colorFilter == "average";
  io::PotreeWriteOptions write;
  if (a.encoding == "brotli")
    write.encoding = io::PotreeEncoding::Brotli;
  else if (a.encoding != "default")
    throw InputError("--encoding expects default or brotli, got '" + a.encoding + "'");
  if (!(a.spacing >= 0) || !std::isfinite(a.spacing)) throw InputError("--spacing expects a positive length");
  if (a.format.empty()) a.format = io::isLazPath(a.output) ? "copc" : "potree";
  if (a.format != "potree" && a.format != "copc")
    throw InputError("--format expects potree or copc, got '" + a.format + "'");
  if (a.format == "copc" && a.encoding != "default")
    throw InputError("--encoding applies to Potree output; COPC nodes are LAZ");
  if (a.indexOn != "cpu" && a.indexOn != "gpu")
    throw InputError("--index-on expects cpu or gpu, got '" + a.indexOn + "'");
  // From here on a signal asks the build to stop: the check below already writes (a probe file it removes).
  gInterrupted = false;
  options.cancel = &gInterrupted;
  InterruptGuard guard;
  // Refused before any point is read: a mistake in the output's name should not cost a read of the input.
  checkOutputFolder(a.output);

  // The device for the index phase, before any point is read: a machine without one says so at once.
  std::unique_ptr<gpu::Context> context;
  std::unique_ptr<render::GpuIndexer> indexer;
  if (a.indexOn == "gpu") {
    gpu::ContextOptions device;
    device.announce = !a.quiet && !a.json;
    context = std::make_unique<gpu::Context>(device);
    indexer = std::make_unique<render::GpuIndexer>(*context);
    options.indexer = indexer.get();
  }

  std::vector<std::filesystem::path> inputs(a.inputs.begin(), a.inputs.end());
  io::PotreeBuildReport report;
  try {
    if (a.format == "copc") {
      io::CopcBuildReport copc = io::buildCopc(inputs, a.output, options);
      report.build = std::move(copc.build);
      report.bytes = copc.bytes;
    } else {
      report = io::buildPotree(inputs, a.output, options, write);
    }
  } catch (const Interrupted&) {
    std::fprintf(stderr, "pointrast: interrupted; %s was not written\n", a.output.c_str());
    return 130;
  }
  std::optional<IndexDevice> device;
  if (indexer) device = IndexDevice{context->info().name, indexer->stats()};
  if (a.json)
    std::printf("%s\n", jsonText(toJson(a, report, device ? &*device : nullptr)).c_str());
  else if (!a.quiet)
    printSummary(a, report, device ? &*device : nullptr);
  return 0;
}

} // namespace

Command addLod(CLI::App& app) {
  auto a = std::make_shared<LodArgs>();
  CLI::App* cmd =
      app.add_subcommand("lod", "Build a level-of-detail octree (Potree 2.0 folder or COPC file) from point "
                                "files");
  cmd->footer(
      "\nThe octree is additive, as PotreeConverter's: every input point is stored once, exactly (its\n"
      "integer coordinates and attributes); the root holds a subsample with one point per cell of a\n"
      "128 x 128 x 128 grid over the cube (spacing = cube edge / 128), each level below one per cell of a\n"
      "grid twice as fine, and a node whose cube holds more than --leaf-points points is split. The\n"
      "point kept in a cell is the one nearest its center; with --color-filter average (the default) it\n"
      "takes the average color of the points it stands for, which removes the color noise of coarse\n"
      "levels. Several inputs merge into one octree (the finest of their scales; 8-bit colors widened\n"
      "next to 16-bit ones).\n"
      "\n"
      "Every attribute of a LAS/LAZ input travels with its point: GPS time, number of returns, scan\n"
      "angle, user data, classification flags, scanner channel, scan direction, edge of flight line, NIR\n"
      "and extra bytes are written as Potree attributes named as PotreeConverter names them (fields\n"
      "that are 0 in every point are left out), or into COPC records. With --no-color-filter every\n"
      "point keeps its own color, and `convert OCTREE out.las` gives back every input record byte for\n"
      "byte, in the input's point format with its extra bytes descriptions.\n"
      "\n"
      "Points are read once and indexed in memory when they fit --memory (about 48 bytes a point, plus\n"
      "their attributes' bytes for LAS inputs);\n"
      "otherwise the build runs out of core, reading the input three times and keeping temporary chunk\n"
      "files in the output's temporary folder. Either way the result is the same, byte for byte, whatever\n"
      "--memory and --threads are. The folder appears only when complete: an error or Ctrl-C leaves\n"
      "nothing behind (a second Ctrl-C stops at once).\n"
      "\n"
      "With --index-on gpu the index phase (sorting each chunk's points into nodes and choosing every\n"
      "level's subsample) runs on the Vulkan device, a few chunks in flight, while the CPU lays out,\n"
      "encodes and writes the nodes; the octree is the same byte for byte. Grids with unequal scales on\n"
      "the axes are indexed on the CPU. On a 16-core machine with a discrete GPU it builds about as fast\n"
      "as the CPU (docs/lod.md), which is why cpu is the default.\n"
      "\n"
      "An output named *.laz (or --format copc) is one COPC 1.0 file instead of a folder: the same nodes\n"
      "and points, each node a LAZ chunk (point format 6, 7 with color), the inputs' WKT coordinate\n"
      "system kept; `info` says whether its inner nodes hold averaged colors.\n"
      "\n"
      "Examples:\n"
      "  pointrast lod scan.las -o scan_octree                 # all cores, in memory if it fits\n"
      "  pointrast lod tiles/*.las -o city --memory 8G         # many tiles, one octree, at most ~8 GiB\n"
      "  pointrast lod big.las -o big --encoding brotli --json # compressed nodes, one JSON summary\n"
      "  pointrast lod scan.las -o coarse --spacing 2 --leaf-points 50k\n"
      "  pointrast lod scan.las -o scan.copc.laz               # one COPC file\n"
      "  pointrast info scan_octree                            # what was built\n"
      "  pointrast render scan_octree -o view.png              # draw all its points");
  cmd->add_option("IN", a->inputs, "Point files: LAS, PLY, XYZ/CSV (several merge into one octree)")
      ->required();
  cmd->add_option("-o,--output", a->output,
                  "Folder (Potree 2.0) or .laz file (COPC 1.0) to create (must not exist)")
      ->required();
  cmd->add_option("--format", a->format, "potree or copc (default: copc for a .laz output, else potree)");
  cmd->add_option("--spacing", a->spacing,
                  "Root spacing in input units, rounded to the cube edge / 2^k (default: edge / 128)");
  cmd->add_option("--leaf-points", a->leafPoints, "A node whose cube holds more points is split (e.g. 20k)")
      ->capture_default_str();
  cmd->add_option("--memory", a->memory,
                  "Memory for the build, e.g. 8G (default: half of the physical memory)");
  cmd->add_option("--threads", a->threads, "Threads (default: all cores)");
  cmd->add_option("--encoding", a->encoding, "Node encoding: default (uncompressed) or brotli")
      ->capture_default_str();
  cmd->add_option("--color-filter", a->colorFilter,
                  "Colors of subsampled points: average (of the points they stand for) or none (their own)")
      ->capture_default_str();
  cmd->add_flag("--no-color-filter", a->noColorFilter,
                "The same as --color-filter none: every point keeps its own color (an exact round trip)");
  cmd->add_option("--index-on", a->indexOn,
                  "Where the points are sorted and subsampled: cpu, or gpu (the Vulkan device: the best one, "
                  "or POINTRAST_DEVICE); the octree is the same byte for byte")
      ->capture_default_str();
  cmd->add_flag("--json", a->json,
                "Print one JSON object: points, nodes, levels, bytes, phases with seconds");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress lines or summary");
  return [a] {
    Progress::setEnabled(!a->quiet && !a->json);
    return runLod(*a);
  };
}

} // namespace pointrast::app
