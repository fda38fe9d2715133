#include "distributed.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string_view>

#include <unistd.h>

#include "base/error.h"
#include "cloud/generate.h"
#include "gpu/device_rank.h"
#include "gpu/shared_types.h"
#include "io/format_table.h"
#include "io/las/las_range.h"
#include "io/las/laz_reader.h"
#include "io/reader.h"
#include "mpi/mpi_job.h"
#include "render/composite.h"

namespace pointrast::app {

namespace {

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Keeps points [first, first + count) of every attribute array the cloud has.
void keepRange(PointCloud& cloud, uint64_t first, uint64_t count) {
  auto keep = [&](auto& values, uint64_t perPoint) {
    if (values.empty()) return;
    values.erase(values.begin() + static_cast<ptrdiff_t>((first + count) * perPoint), values.end());
    values.erase(values.begin(), values.begin() + static_cast<ptrdiff_t>(first * perPoint));
    values.shrink_to_fit();
  };
  keep(cloud.positions, 3);
  keep(cloud.colors, 1);
  keep(cloud.intensity, 1);
  keep(cloud.classification, 1);
  keep(cloud.returnNumber, 1);
  keep(cloud.pointSourceId, 1);
}

// Test hook (docs/mpi.md): rank 0 writes the composited words, 8 B a pixel little-endian, to this file.
void dumpWords(std::span<const uint64_t> words) {
  const char* path = std::getenv("POINTRAST_MPI_WORDS");
  if (!path || !*path) return;
  const std::filesystem::path target(path), partial = target.string() + ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(words.data()), std::streamsize(words.size() * 8));
    if (!out) throw InputError(target.string() + ": cannot write the composited words");
  }
  std::filesystem::rename(partial, target);
}

} // namespace

bool compositesInSteps(const MethodInfo& info) {
  return info.output == MethodOutput::Blend;
}

bool distributedRun() {
  return mpi::Job::get().launched();
}

// Which device this rank took and why, for announceRanks(): ranks of one host must not share a GPU
// unawares, and a device's name alone does not say which of several alike it is.
static std::string chosenDevice;

void chooseRankDevice(gpu::ContextOptions& options) {
  const mpi::Job& job = mpi::Job::get();
  if (!job.launched()) return;
  options.announce = false;
  if (options.deviceIndex) {
    chosenDevice = "device " + std::to_string(*options.deviceIndex) + " (--device)";
    return;
  }
  if (const char* env = std::getenv("POINTRAST_DEVICE"); env && *env) {
    chosenDevice = std::string("device ") + env + " (POINTRAST_DEVICE)";
    return; // the Context reads it
  }
  const std::vector<gpu::DeviceInfo> devices = gpu::listDevices();
  int best = 0;
  for (const gpu::DeviceInfo& d : devices)
    best = std::max(best, gpu::deviceTypeRank(d.type));
  std::vector<uint32_t> candidates;
  for (uint32_t i = 0; i < devices.size(); ++i)
    if (gpu::deviceTypeRank(devices[i].type) == best) candidates.push_back(i);
  if (candidates.empty()) return;
  options.deviceIndex = candidates[job.localRank() % candidates.size()];
  chosenDevice = "device " + std::to_string(*options.deviceIndex) + " of " + std::to_string(devices.size());
}

std::vector<std::string> announceRanks(const gpu::Context& context, bool quiet) {
  mpi::Job& job = mpi::Job::get();
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0) std::snprintf(host, sizeof host, "unknown host");
  const std::string mine = std::string(host) + ": " + context.info().name + " (" + context.info().typeName +
                           ")" + (chosenDevice.empty() ? "" : ", " + chosenDevice) +
                           (context.validationEnabled() ? ", validation on" : "");
  std::vector<std::string> all = job.gatherText(mine);
  if (job.root() && !quiet)
    for (size_t r = 0; r < all.size(); ++r)
      std::fprintf(stderr, "rank %zu of %zu: %s\n", r, all.size(), all[r].c_str());
  return all;
}

void checkDistributed(const RenderSettings& settings, bool cameraPath, bool spheres) {
  if (cameraPath) throw InputError("--path renders on one process; under mpirun render draws single frames");
  if (spheres) throw InputError("the sphere methods render on one process, not under mpirun");
  const MethodInfo& info = settings.method.info();
  if (info.output == MethodOutput::ColorOnly)
    throw InputError(std::string(info.name) +
                     " keeps no depth per pixel, so ranks' frames cannot be composited; under mpirun use a "
                     "closest-point method (atomicmin, the batch methods, lod)");
}

PointCloud loadShare(const InputSpec& spec) {
  mpi::Job& job = mpi::Job::get();
  InputSpec mine = spec;
  mine.progress = spec.progress && job.root();
  const std::string source = spec.source.empty() ? kDemoScene : spec.source;
  // A generated scene in its own order: each rank generates its points only. Any other input is loaded
  // (and ordered) whole, so the points of the ranges are exactly those one process would draw.
  if (!pathExists(source) && isSceneName(source) && spec.order == Order::Original) {
    const uint64_t total = spec.source.empty() ? kDemoPoints : spec.points;
    const mpi::Range range = mpi::rangeOf(total, shared::kBatchPoints, job.rank(), job.size());
    GenerateOptions options;
    options.points = total;
    options.seed = spec.seed;
    options.progress = mine.progress;
    options.first = range.first;
    options.count = range.count;
    options.classification = spec.classification;
    PointCloud cloud = generateScene(parseScene(source), options);
    cloud.bounds = job.unionOf(cloud.bounds);
    return cloud;
  }
  // A LAS file in its own order: each rank reads only the bytes of its records, the same ranges the
  // whole file would be cut into. The ranks agree on the file's color depth (any value above 255 anywhere
  // makes it 16-bit) and its bounds.
  const io::FormatInfo* format = pathExists(source) ? io::detectFormat(source) : nullptr;
  if (format && std::string_view(format->name) == "LAS" && spec.order == Order::Original) {
    const uint64_t total = io::statedPointCount(source).value_or(0);
    const mpi::Range range = mpi::rangeOf(total, shared::kBatchPoints, job.rank(), job.size());
    io::ReadOptions options;
    options.progress = mine.progress;
    uint16_t colorMax = 0;
    PointCloud cloud = io::readLasRecords(source, options, range.first, range.count, &colorMax);
    if (job.maxOf(double(colorMax)) > 255 && colorMax <= 255)
      std::fill(cloud.colors.begin(), cloud.colors.end(), packRgba(0, 0, 0));
    cloud.bounds = job.unionOf(cloud.bounds);
    return cloud;
  }
  // A LAZ or COPC file in its own order: each rank reads and decodes only the chunks that hold its
  // records. Colors: the file is 16-bit when any rank read a 16-bit chunk (readLaz()'s rule).
  if (format && (std::string_view(format->name) == "LAZ" || std::string_view(format->name) == "COPC") &&
      spec.order == Order::Original) {
    const uint64_t total = io::statedPointCount(source).value_or(0);
    const mpi::Range range = mpi::rangeOf(total, shared::kBatchPoints, job.rank(), job.size());
    io::ReadOptions options;
    options.progress = mine.progress;
    io::LazColorDepths depths;
    PointCloud cloud = io::readLazRange(source, options, range.first, range.count, &depths);
    if (job.maxOf(depths.any16 ? 1.0 : 0.0) > 0) io::blackenEightBit(cloud, depths);
    cloud.bounds = job.unionOf(cloud.bounds);
    return cloud;
  }
  PointCloud cloud = loadInput(mine);
  const mpi::Range range = mpi::rangeOf(cloud.size(), shared::kBatchPoints, job.rank(), job.size());
  keepRange(cloud, range.first, range.count);
  job.check(); // every rank has its share (or the job hears which failed)
  return cloud;
}

DisplayColorMode agreeColors(const DisplayColorMode& mine) {
  DisplayColorMode agreed = mine;
  mpi::Job::get().broadcast(&agreed, sizeof agreed);
  return agreed;
}

RenderSettings rankSettings(const RenderSettings& settings) {
  RenderSettings s = settings;
  s.post = PostSettings{};
  s.captureWords = true;
  return s;
}

// Every rank's render time and points into `out` (a collective: every rank calls it).
static void gatherRankStats(const FrameStats& stats, CompositeStats& out) {
  mpi::Job& job = mpi::Job::get();
  out.ranks = job.size();
  out.rankMs = job.gatherOf(stats.medianMs);
  out.renderMs = job.maxOf(stats.medianMs);
  out.points = job.sumOf(stats.points);
  for (double points : job.gatherOf(double(stats.points)))
    out.rankPoints.push_back(uint64_t(points));
}

namespace {

// The MIN of every rank's words into rank 0's, timed on its own (all ranks are there first, so the time
// is not a wait for the slowest rank).
double minWords(std::span<uint64_t> words) {
  mpi::Job& job = mpi::Job::get();
  job.check();
  const auto start = std::chrono::steady_clock::now();
  job.minToRoot(words);
  return msSince(start);
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

} // namespace

std::vector<uint32_t> compositeWords(CompositeResolver& resolver, std::span<uint64_t> words,
                                     const Camera& camera, const RenderSettings& settings, double int40Scale,
                                     CompositeStats& out, std::vector<uint64_t>* ended, bool composited) {
  mpi::Job& job = mpi::Job::get();
  if (!composited) out.compositeMs = minWords(words);
  out.compositePath = job.compositePath();
  out.bytesMoved = uint64_t(job.size() - 1) * words.size() * 8;
  if (!job.root()) return {};
  dumpWords(words);
  const auto start = std::chrono::steady_clock::now();
  std::vector<uint32_t> image = resolver.resolve(words, camera, settings, int40Scale, &out.post, ended);
  out.resolveMs = msSince(start);
  return image;
}

std::vector<uint32_t> compositeFrame(gpu::Context& context, Renderer& renderer, const Camera& camera,
                                     const RenderSettings& settings, double int40Scale,
                                     const FrameStats& stats, CompositeStats& out) {
  const std::span<uint64_t> words =
      mpi::Job::get().compositeBuffer(uint64_t(renderer.width()) * renderer.height());
  gatherRankStats(stats, out);
  // The read-back and the composite of the last frame, repeated as the frames were (up to 10 times; the
  // words are the same each time), their medians reported: the first of them also pays for mapping the
  // memory they use.
  std::vector<double> readback, composite;
  for (uint32_t i = 0; i < std::clamp<uint32_t>(settings.frames, 1, 10); ++i) {
    const auto start = std::chrono::steady_clock::now();
    renderer.framebufferWords(words);
    readback.push_back(msSince(start));
    composite.push_back(minWords(words));
  }
  out.readbackMs = median(readback);
  out.compositeMs = median(composite);
  CompositeResolver resolver(context, renderer.width() / renderer.eyes(), renderer.height(), renderer.eyes());
  std::vector<uint32_t> image = compositeWords(resolver, words, camera, settings, int40Scale, out, nullptr, true);
  // The first resolve makes the resolve stage's pipelines and buffers; a viewer pays that once. The
  // resolve reported is the median of the repeats after it, as a viewer's later frames pay it.
  out.resolveFirstMs = out.resolveMs;
  if (mpi::Job::get().root() && settings.frames > 1) {
    std::vector<double> resolves;
    for (uint32_t i = 1; i < std::min<uint32_t>(settings.frames, 10); ++i) {
      const auto start = std::chrono::steady_clock::now();
      resolver.resolve(words, camera, settings, int40Scale, nullptr, nullptr);
      resolves.push_back(msSince(start));
    }
    out.resolveMs = median(resolves);
  }
  return image;
}

std::vector<uint32_t> compositeHqsFrame(Renderer& renderer, std::span<const GpuScene* const> scenes,
                                        const Camera& camera, const RenderSettings& settings,
                                        const FrameStats& stats, CompositeStats& out) {
  return compositeHqsFrame(
      renderer, [&](const RenderSettings& s) { return renderer.render(scenes, camera, s); }, settings, stats,
      out);
}

std::vector<uint32_t> compositeHqsFrame(Renderer& renderer,
                                        const std::function<FrameStats(const RenderSettings&)>& draw,
                                        const RenderSettings& settings, const FrameStats& stats,
                                        CompositeStats& out) {
  mpi::Job& job = mpi::Job::get();
  gatherRankStats(stats, out);
  RenderSettings step = rankSettings(settings);
  step.captureWords = false;
  step.frames = 1;
  step.warmup = 0;
  step.hqsPass = HqsPass::Depth;
  draw(step);
  auto start = std::chrono::steady_clock::now();
  std::vector<uint64_t> depths = renderer.hqsDepths();
  out.readbackMs = msSince(start);
  job.check(); // all ranks are here: the composite's time is its own
  start = std::chrono::steady_clock::now();
  job.minToAll(depths); // every rank blends against the closest depth of all
  out.compositeMs = msSince(start);
  renderer.setHqsDepths(depths);
  step.hqsPass = HqsPass::Blend;
  draw(step);
  start = std::chrono::steady_clock::now();
  std::vector<uint64_t> sums = renderer.hqsSums();
  out.readbackMs += msSince(start);
  job.check();
  start = std::chrono::steady_clock::now();
  job.sumToRoot(sums);
  out.compositeMs += msSince(start);
  // The depths go to every rank and back (8 B a pixel each way), the sums to rank 0 (16 B a pixel).
  out.bytesMoved = uint64_t(job.size() - 1) * depths.size() * 32;
  if (!job.root()) return {};
  start = std::chrono::steady_clock::now();
  renderer.setHqsSums(sums);
  step = settings;
  step.frames = 1;
  step.warmup = 0;
  step.hqsPass = HqsPass::Resolve;
  const FrameStats resolved = draw(step);
  out.post = resolved.post;
  std::vector<uint32_t> image = renderer.image();
  out.resolveMs = msSince(start);
  return image;
}

nlohmann::json compositeJson(const CompositeStats& s) {
  nlohmann::json j;
  j["ranks"] = s.ranks;
  j["render_ms"] = s.renderMs;
  j["rank_render_ms"] = s.rankMs;
  j["rank_points"] = s.rankPoints;
  j["readback_ms"] = s.readbackMs;
  if (!s.compositePath.empty()) j["composite_path"] = s.compositePath;
  j["composite_ms"] = s.compositeMs;
  j["resolve_ms"] = s.resolveMs;
  if (s.resolveFirstMs > 0) j["resolve_first_ms"] = s.resolveFirstMs;
  // A frame's stages one after another on rank 0, as a viewer runs them: what bounds its frame rate.
  j["frame_ms"] = s.renderMs + s.readbackMs + s.compositeMs + s.resolveMs;
  j["bytes_moved"] = s.bytesMoved;
  j["devices"] = s.devices;
  return j;
}

void printCompositeSummary(const CompositeStats& s) {
  std::printf(
      "  %u ranks: slowest rank %.3f ms median GPU time; composite %.3f ms (MIN of %.1f MB of words), "
      "readback %.3f ms, resolve %.3f ms on rank 0\n",
      s.ranks, s.renderMs, s.compositeMs, double(s.bytesMoved) / 1e6, s.readbackMs, s.resolveMs);
}

} // namespace pointrast::app
