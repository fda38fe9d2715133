// pointrast render [FILE|SCENE] -o OUT.png ...
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "base/text.h"
#include "cli_util.h"
#include "cloud/attribute_colors.h"
#include "cloud/generate.h"
#include "cloud/particles_generate.h"
#include "commands.h"
#include "distributed.h"
#include "gpu/context.h"
#include "gpu/shared_types.h"
#include "input.h"
#include "options.h"
#include "io/annotations_file.h"
#include "io/format_table.h"
#include "io/output_check.h"
#include "io/writer.h"
#include "mpi/mpi_job.h"
#include "render/composite.h"
#include "render/clock_settle.h"
#include "render/lod/lod_scene.h"
#include "render/overlay.h"
#include "render/pick.h"
#include "render/renderer.h"
#include "render/spheres/sphere_renderer.h"
#include "render_filter.h"
#include "render_path.h"
#include "report/pick_json.h"
#include "report/stats_json.h"

namespace pointrast::app {

namespace {

// Said on stderr when the timed frames still spread like clocks that were rising (timeSettled).
void warnUnsettled(bool settled, double medianMs, double minMs) {
  if (settled) return;
  std::fprintf(stderr,
               "render: GPU clocks did not settle: median %.3f ms, fastest frame %.3f ms; the median is not the "
               "device's speed (time it with `pointrast bench`, which settles them)\n",
               medianMs, minMs);
}


struct RenderArgs {
  std::string input, output, eye, target, up = "0,0,1", background = "0,0,0", order = "original";
  std::string method = "atomicmin", points = "1M", depth = "float";
  bool methodGiven = false; // --method was on the command line (the default is atomicmin)
  std::string precision = "adaptive"; // batch methods
  LodArgs lod;                        // LOD methods
  std::string layout = "auto";        // sphere methods
  std::string billboard;              // sphere methods that rasterize billboards; empty: screen
  bool conservative = false;          // the same: VK_EXT_conservative_rasterization
  std::optional<uint32_t> meshlet;    // sphere-mesh-*: spheres per mesh workgroup (31 or 15)
  bool taskCull = false;              // sphere-mesh-*: cull in a task shader first
  uint32_t width = 1920, height = 1080, frames = 10, parts = 1;
  uint32_t frame = 0; // sphere methods: MMPLD frame
  float radius = 0;   // sphere methods: radius of points drawn as spheres, or replacing the file's
  double fov = 60, nearW = 0;
  uint64_t seed = 1;
  std::optional<uint32_t> device;
  bool json = false, quiet = false;
  PathOutput path; // --path: a camera path into a video or PNG frames instead of -o
  std::string annotations; // --annotations: measurements drawn over the image
  LookArgs look; // point methods: coloring and the resolve stage
  FilterArgs filter; // point methods: clip volumes and attribute filters
  std::string pick;  // --pick X,Y: the point drawn at that pixel, in the JSON
  StereoArgs eyes; // stereo (batch and LOD methods) and foveated LOD
};

// The PNG file(s) of a frame: -o, or with --stereo-layout separate the two eyes as OUT-left.png and
// OUT-right.png.
std::vector<std::string> outputFiles(const RenderArgs& a) {
  if (!a.eyes.stereo || a.eyes.stereoLayout != "separate") return {a.output};
  const std::filesystem::path out(a.output);
  std::vector<std::string> files;
  for (const char* eye : {"-left", "-right"}) {
    std::filesystem::path file = out;
    file.replace_filename(out.stem().string() + eye + out.extension().string());
    files.push_back(file.string());
  }
  return files;
}

// Writes the frame to outputFiles(a): one image (both eyes side by side in stereo) or one per eye.
void writeOutput(const RenderArgs& a, const std::vector<uint32_t>& pixels) {
  const std::vector<std::string> files = outputFiles(a);
  const uint32_t eyes = a.eyes.stereo ? 2 : 1;
  if (files.size() == 1) {
    io::writePng(files[0], a.width * eyes, a.height, pixels.data());
    return;
  }
  for (uint32_t e = 0; e < 2; ++e) {
    std::vector<uint32_t> eye(uint64_t(a.width) * a.height);
    for (uint32_t y = 0; y < a.height; ++y)
      std::copy_n(pixels.begin() + (uint64_t(y) * 2 * a.width + uint64_t(e) * a.width), a.width,
                  eye.begin() + uint64_t(y) * a.width);
    io::writePng(files[e], a.width, a.height, eye.data());
  }
}

nlohmann::json outputJson(const RenderArgs& a) {
  const std::vector<std::string> files = outputFiles(a);
  return files.size() == 1 ? nlohmann::json(files[0]) : nlohmann::json(files);
}

nlohmann::json stereoJson(const RenderArgs& a, const StereoSettings& s, const Camera& camera) {
  nlohmann::json j;
  j["ipd"] = eyeSeparation(camera, s);
  const double convergence = convergenceDistance(camera, s);
  j["convergence"] = std::isinf(convergence) ? nlohmann::json("inf") : nlohmann::json(convergence);
  j["layout"] = a.eyes.stereoLayout;
  return j;
}

// What every render checks before reading anything: the output, the image size, the frames, and the camera
// options a user gave, each named.
void checkCommonArgs(const RenderArgs& a) {
  // -o is the single image; --path renders a camera path into --video or --frames-dir instead.
  const bool pathMode = !a.path.path.empty();
  if (!pathMode && (!a.path.video.empty() || !a.path.framesDir.empty()))
    throw InputError("--video and --frames-dir need --path (a camera path)");
  if (pathMode == !a.output.empty())
    throw InputError(pathMode ? "--path replaces -o: give one of them" : "-o is required");
  if (pathMode && isSphereMethodName(a.method))
    throw InputError("--path renders the point methods, not " + a.method);
  if (!pathMode && std::filesystem::path(a.output).extension() != ".png")
    throw InputError("-o " + a.output + ": the output must be a .png file");
  if (!pathMode) io::checkOutputTarget(a.output, "-o");
  if (a.width == 0 || a.height == 0) throw InputError("--width and --height must be at least 1");
  if (a.frames == 0) throw InputError("--frames must be at least 1");
  if (!a.annotations.empty() && isSphereMethodName(a.method))
    throw InputError("--annotations draws over the point methods, not " + a.method);
  if (!(a.fov > 0 && a.fov < 180)) throw InputError("--fov must be between 0 and 180 degrees");
  if (!(a.nearW >= 0) || !std::isfinite(a.nearW)) throw InputError("--near must be a number >= 0");
  if (!a.target.empty() && a.eye.empty()) throw InputError("--target needs --eye");
  if (!a.eye.empty()) {
    parseVec3(a.eye, "--eye");
    parseVec3(a.up, "--up");
    if (!a.target.empty()) parseVec3(a.target, "--target");
  }
}

// What a camera problem means in terms of the options that set the camera.
std::string cameraOptionText(CameraProblem problem) {
  switch (problem) {
  case CameraProblem::EyeIsTarget:
    return "--eye and --target must differ (--target defaults to the center of the bounds)";
  case CameraProblem::UpIsZero:
    return "--up must not be zero";
  case CameraProblem::UpAlongView:
    return "--up is parallel to the view direction; give another --up";
  default:
    return describeCameraProblem(problem); // the rest was checked with its option's name already
  }
}

// The camera of --eye/--target/--up, or the overview of `bounds`. The data is checked first (coordinates
// pointrast can place a camera among), so what fails afterwards is an option the user gave.
Camera renderCamera(const RenderArgs& a, const Bounds& bounds, const std::string& source,
                    std::span<const glm::dvec3> framing = {}) {
  checkCoordinateRange(bounds, source);
  Camera camera = overviewCamera(bounds, double(a.width) / double(a.height), a.fov, framing);
  if (!a.eye.empty()) {
    camera.eye = parseVec3(a.eye, "--eye");
    camera.target = a.target.empty() ? bounds.center() : parseVec3(a.target, "--target");
    camera.up = parseVec3(a.up, "--up");
  }
  camera.nearW = a.nearW;
  if (auto problem = findCameraProblem(camera))
    throw InputError(a.eye.empty() ? source + ": no overview camera: " + describeCameraProblem(*problem)
                                   : cameraOptionText(*problem));
  return camera;
}

// Writes the image only once the frame can be trusted and its JSON line is made: a validation error, or a
// result that cannot be printed, leaves no PNG behind. Then prints the JSON line, or calls `summary`.
void finishImage(const RenderArgs& a, const gpu::Context& context, const std::vector<uint32_t>& pixels,
                 const std::function<nlohmann::json()>& json, const std::function<void()>& summary) {
  if (context.validationErrors() > 0)
    throw InternalError("the Vulkan validation layer reported " + std::to_string(context.validationErrors()) +
                        " error(s), above; no image was written");
  const std::string line = a.json ? jsonText(json()) : std::string();
  writeOutput(a, pixels);
  if (a.json)
    std::printf("%s\n", line.c_str());
  else if (!a.quiet)
    summary();
}

double perSecond(uint64_t items, double medianMs) {
  return medianMs > 0 ? double(items) / (medianMs * 1e-3) : 0.0;
}

bool isMeshMethod(SphereMethod method) {
  return method == SphereMethod::MeshPoints || method == SphereMethod::MeshTriangles;
}

gpu::ContextOptions contextOptions(const RenderArgs& a) {
  gpu::ContextOptions options;
  options.deviceIndex = a.device;
  options.announce = !a.quiet;
  chooseRankDevice(options); // under mpirun: the device of this rank
  return options;
}

// The image size, the frames and their GPU times, as both kinds of render report them.
void addTimes(nlohmann::json& j, const RenderArgs& a, uint32_t frames, double medianMs, double minMs,
              double maxMs) {
  j["width"] = a.width;
  j["height"] = a.height;
  j["frames"] = frames;
  j["median_ms"] = medianMs;
  j["min_ms"] = minMs;
  j["max_ms"] = maxMs;
}

std::string hashText(const std::vector<uint32_t>& pixels) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx",
                static_cast<unsigned long long>(imageHash(pixels.data(), pixels.size())));
  return hex;
}

// Whether any option of the resolve stage or of coloring was given (the sphere methods take none).
bool postOrColorGiven(const RenderArgs& r) {
  const LookArgs& a = r.look;
  return a.color != "auto" || !a.colorRange.empty() || a.pointSize != 1 || a.pointSizeMax != 16 ||
         a.pointShape != "square" || a.pointSizeMode != "fixed" || a.dilate != 0 || a.edl || a.edlStrength ||
         a.edlRadius;
}

// The color mode of a loaded cloud: nullopt for auto.
std::optional<DisplayColorMode> colorMode(const RenderArgs& a, const PointCloud& cloud) {
  const ColorChoice choice = colorChoice(a.look);
  if (!choice.source) return std::nullopt;
  return displayColorMode(cloud, *choice.source, choice.range);
}

// The resolve stage's settings and per-pass GPU times.
nlohmann::json postJson(const PostSettings& post, const PostStats& stats) {
  nlohmann::json j;
  j["point_size"] = post.pointSize;
  j["point_shape"] = pointShapeName(post.shape);
  j["point_size_mode"] = pointSizeModeName(post.sizeMode);
  if (post.sizeMode == PointSizeMode::Attenuated) j["point_size_max"] = post.maxPointSize;
  j["dilate"] = post.dilate;
  j["edl_strength"] = post.edlStrength;
  if (post.edlStrength > 0) j["edl_radius"] = post.edlRadius;
  j["splat_ms"] = stats.splatMs;
  j["dilate_ms"] = stats.dilateMs;
  j["compose_ms"] = stats.composeMs;
  return j;
}

void printPostStats(const PostSettings& post, const PostStats& stats) {
  std::printf("  resolve stage: point size %.3f ms, dilation %.3f ms, compose%s %.3f ms (median GPU time)\n",
              stats.splatMs, stats.dilateMs, post.edlStrength > 0 ? " + EDL" : "", stats.composeMs);
}

// The sphere options of the command line, checked before anything is read.
SphereSettings sphereSettings(const RenderArgs& a) {
  SphereSettings settings;
  settings.method = parseSphereMethod(a.method);
  settings.background = parseRgb(a.background, "--background");
  settings.frames = a.frames;
  if (a.order != "original" || a.depth != "float" || a.parts != 1 || a.precision != "adaptive")
    throw InputError("--order, --depth, --parts and --precision apply to the point methods, not to " +
                     a.method);
  if (postOrColorGiven(a))
    throw InputError("--color, --point-size, --dilate and --edl apply to the point methods, not to " +
                     a.method);
  if (!a.billboard.empty()) settings.billboard = parseSphereBillboard(a.billboard);
  settings.conservative = a.conservative;
  if ((!a.billboard.empty() || a.conservative) && !sphereMethodTakesBillboards(settings.method))
    throw InputError(
        "--billboard and --conservative apply to the sphere methods that rasterize billboards (" +
        billboardMethodNames() + "), not to " + a.method);
  const bool mesh = isMeshMethod(settings.method);
  if ((a.meshlet || a.taskCull) && !mesh)
    throw InputError("--meshlet and --task-cull apply to sphere-mesh-points and sphere-mesh-tris, not to " +
                     a.method);
  settings.meshlet = a.meshlet.value_or(shared::kSphereMeshletLarge);
  settings.taskCull = a.taskCull;
  if (settings.meshlet != shared::kSphereMeshletLarge && settings.meshlet != shared::kSphereMeshletSmall)
    throw InputError("--meshlet takes " + std::to_string(shared::kSphereMeshletLarge) + " or " +
                     std::to_string(shared::kSphereMeshletSmall) + " (spheres per mesh workgroup), not " +
                     std::to_string(settings.meshlet));
  return settings;
}

nlohmann::json sphereJson(const gpu::Context& context, const SphereSettings& settings, const ParticleSet& set,
                          const GpuParticles& particles, const SphereStats& stats, const Camera& camera,
                          const RenderArgs& a, const std::vector<uint32_t>& pixels) {
  nlohmann::json j;
  j["device"] = context.info().name;
  j["device_type"] = context.info().typeName;
  j["method"] = sphereMethodName(settings.method);
  j["layout"] = particleLayoutName(particles.layout());
  if (sphereMethodTakesBillboards(settings.method)) {
    j["billboard"] = sphereBillboardName(settings.billboard);
    j["conservative"] = settings.conservative;
  }
  if (isMeshMethod(settings.method)) {
    j["meshlet"] = settings.meshlet;
    j["task_cull"] = settings.taskCull;
  }
  if (settings.method == SphereMethod::RayTracing || settings.method == SphereMethod::Compute)
    j["build_ms"] = stats.buildMs; // sphere-rt's structures, sphere-compute's batch bounds
  j["input"] = set.source;
  j["particles"] = stats.particles;
  addTimes(j, a, stats.frames, stats.medianMs, stats.minMs, stats.maxMs);
  j["particles_per_second"] = perSecond(stats.particles, stats.medianMs);
  j["large_chunks"] = stats.largeChunks;
  j["spilled_spheres"] = stats.spilledSpheres;
  if (settings.method == SphereMethod::Compute) { // occlusion culling: batches of 128 particles
    j["batches"] = stats.batches;
    j["visible_batches"] = stats.visibleBatches;
  }
  j["clamped_spheres"] = stats.clampedSpheres;
  j["camera"] = describeCamera(camera);
  j["image_hash"] = hashText(pixels);
  j["output"] = a.output;
  return j;
}

// The sphere methods (--method sphere-*): particles from an MMPLD file, a particle scene, or points drawn
// as spheres of --radius, through the SphereRenderer.
int runRenderSpheres(const RenderArgs& a) {
  const SphereSettings settings = sphereSettings(a);
  ParticleUploadOptions upload;
  upload.progress = !a.quiet;
  if (a.layout != "auto") upload.layout = parseParticleLayout(a.layout);

  ParticleInputSpec spec;
  spec.source = a.input;
  spec.frame = a.frame;
  spec.radius = a.radius;
  spec.particles = parseCount(a.points, "--points");
  spec.seed = a.seed;
  spec.progress = !a.quiet;
  // Header counts first (a bad file is refused before the device starts), then the device's memory: a
  // file too large for it is refused before its particles are read.
  const std::optional<uint64_t> stated = statedParticles(spec);
  gpu::Context context(contextOptions(a));
  std::string why;
  if (stated && !particlesFit(context, upload.layout, *stated, &why))
    throw UnsupportedError((a.input.empty() ? kDemoParticleScene : a.input) + ": " + why);
  if (!SphereRenderer::supports(context, settings, &why)) throw UnsupportedError(why); // before the read
  ParticleSet set = loadParticles(spec);
  if (upload.layout && !layoutHolds(*upload.layout, set, &why)) throw InputError(why);
  const Camera camera = renderCamera(a, sphereBounds(set), set.source);

  SphereRenderer renderer(context, a.width, a.height);
  GpuParticles particles(context, set, upload);
  settleClocksWith(context, settings,
                   [&](const SphereSettings& s) { return renderer.render(particles, camera, s); });
  bool settled = true;
  const SphereStats stats = timeSettled(
      context, settings, [&](const SphereSettings& s) { return renderer.render(particles, camera, s); }, settled);
  warnUnsettled(settled, stats.medianMs, stats.minMs);
  const std::vector<uint32_t> pixels = renderer.image();
  finishImage(
      a, context, pixels,
      [&] { return sphereJson(context, settings, set, particles, stats, camera, a, pixels); },
      [&] {
        std::printf(
            "%s: %s particles (%s), %ux%u, %s: %.3f ms median GPU time over %u frames (%.3f..%.3f), %s "
            "particles/s\n",
            a.output.c_str(), humanCount(double(stats.particles)).c_str(),
            particleLayoutName(particles.layout()), a.width, a.height, sphereMethodName(settings.method),
            stats.medianMs, stats.frames, stats.minMs, stats.maxMs,
            humanCount(perSecond(stats.particles, stats.medianMs)).c_str());
        if (settings.method == SphereMethod::RayTracing)
          std::printf("  acceleration structures built in %.3f ms of GPU time (not in the frame times)\n",
                      stats.buildMs);
      });
  return 0;
}

void printLodStats(const lod::LodStats& s, const BatchStats& b) {
  std::printf("  nodes: %llu selected (%s points%s), %llu drawn in %u pass%s, %llu rendered; points: %s "
              "processed, %s rendered\n",
              (unsigned long long)s.nodesSelected, humanCount(double(s.pointsSelected)).c_str(),
              s.budgetReached ? ", point budget reached" : "", (unsigned long long)s.nodesDrawn, s.passes,
              s.passes == 1 ? "" : "es", (unsigned long long)b.batchesRendered,
              humanCount(double(b.pointsProcessed)).c_str(), humanCount(double(b.pointsRendered)).c_str());
  std::printf("  streamed %s of %llu nodes in %.2f s (%s uploaded, node cache %s)\n",
              bytesText(s.bytesStreamed).c_str(), (unsigned long long)s.nodesLoaded, s.streamSeconds,
              bytesText(s.bytesUploaded).c_str(), bytesText(s.cacheBytes).c_str());
}

// The JSON line of an octree render.
nlohmann::json octreeJson(const gpu::Context& context, const RenderSettings& settings,
                          const lod::OctreeMetadata& octree, const ColorChoice& colors,
                          const FrameStats& stats, const Camera& camera, const RenderArgs& a,
                          const std::vector<uint32_t>& pixels) {
  nlohmann::json j;
  j["device"] = context.info().name;
  j["device_type"] = context.info().typeName;
  j["method"] = methodName(settings.method);
  j["input"] = octree.source;
  j["format"] = octree.format;
  j["octree_points"] = octree.pointCount;
  j["points"] = stats.points;
  addTimes(j, a, stats.frames, stats.medianMs, stats.minMs, stats.maxMs);
  j["points_per_second"] = perSecond(stats.points, stats.medianMs);
  j["precision"] = a.precision;
  j["min_node_px"] = settings.minNodePx;
  j["point_budget"] = settings.pointBudget;
  j["batch_stats"] = report::batchStatsJson(*stats.batch);
  j["lod_stats"] = report::lodStatsJson(*stats.lod);
  if (settings.foveation.enabled)
    j["foveation"] = {{"radius", settings.foveation.radius}, {"periphery", settings.foveation.periphery}};
  if (a.eyes.stereo) j["stereo"] = stereoJson(a, settings.stereo, camera);
  if (colors.source) j["color"] = colorSourceName(*colors.source);
  if (stats.post) j["post"] = postJson(settings.post, *stats.post);
  j["camera"] = describeCamera(camera);
  j["image_hash"] = hashText(pixels);
  j["output"] = outputJson(a);
  return j;
}

// Draws the annotations over the frame the renderer drew last with `camera`.
void drawOverlay(Renderer& renderer, const Camera& camera, const Bounds& bounds, const Annotations& annotations,
                 std::vector<uint32_t>& pixels) {
  const std::vector<uint64_t> words = renderer.framebufferWords();
  const double nearW = camera.nearW > 0 ? camera.nearW : defaultNear(bounds);
  drawAnnotations({pixels, renderer.width(), renderer.height(), words}, camera, nearW, annotations);
}

InputSpec renderInputSpec(const RenderArgs& a, const RenderSettings& settings);

// The LOD methods (--method lod, lod-hqs): an octree streamed through the node cache.
int runRenderOctree(const RenderArgs& a, RenderSettings settings,
                    const std::optional<Annotations>& annotations) {
  if (!a.path.path.empty())
    throw InputError("--path renders the methods that draw a loaded cloud, not " + a.method + " (an octree)");
  if (a.order != "original" || a.parts != 1 || a.depth != "float")
    throw InputError("--order, --parts and --depth do not apply to " + a.method +
                     ", which draws an octree's nodes in their stored order");
  checkOctreeFilter(settings.filter, a.method);
  const LodValues lod = lodValues(a.lod);
  settings.minNodePx = lod.minNodePx;
  settings.pointBudget = lod.pointBudget;
  settings.post = postSettings(a.look);
  settings.stereo = stereoSettings(a.eyes);
  settings.foveation = foveation(a.eyes);
  const ColorChoice colors = colorChoice(a.look);
  const bool distributed = distributedRun(); // under mpirun: this rank draws its share of the selection
  if (distributed) checkDistributed(settings, false, false);
  if (!a.pick.empty() && (distributed || settings.method.info().output != MethodOutput::Closest))
    throw InputError("--pick on an octree reads the lod method's frame on one process, not " + a.method +
                     (distributed ? " under mpirun" : ""));
  if (a.input.empty() || isSceneName(a.input))
    throw InputError((a.input.empty() ? std::string("the demo scene") : a.input) + " is a generated scene; " +
                     a.method + " draws octrees (" + io::formatList(io::FormatUse::Octree) +
                     "): build one with `pointrast lod FILE -o DIR`");
  lod::LodOptions options;
  options.gpuBytes = lod.gpuBytes;
  options.colorSource = colors.source;
  options.colorRange = colors.range;
  options.shareIndex = mpi::Job::get().rank();
  options.shares = mpi::Job::get().size();
  // The input opens as the viewers open it (app/input.h): an octree as it is; a cloud file is built into
  // the octree cache once and streamed from there.
  SceneOptions sceneOptions;
  sceneOptions.method = settings.method;
  sceneOptions.onNote = [&a](const std::string& line) {
    if (!a.quiet) std::fprintf(stderr, "%s\n", line.c_str());
  };
  const InputSpec spec = renderInputSpec(a, settings);
  view::SceneInput input = distributed ? openSceneShare(spec, sceneOptions) : openScene(spec, sceneOptions);
  std::unique_ptr<lod::NodeSource> source = std::move(input.octree);
  if (!source) throw InternalError(a.input + " opened without an octree for " + a.method);
  const lod::OctreeMetadata& octree = source->metadata();
  const Camera camera = renderCamera(a, octree.bounds.empty() ? octree.cube : octree.bounds, octree.source,
                                     framingSample(*source));

  gpu::Context context(contextOptions(a));
  CompositeStats composite;
  if (distributed) composite.devices = announceRanks(context, a.quiet);
  std::string why;
  if (!Renderer::supports(context, settings.method, &why)) throw UnsupportedError(why);
  Renderer renderer(context, a.width, a.height, a.eyes.stereo ? 2 : 1);
  lod::LodScene scene(context, *source, options);
  const RenderSettings drawn = distributed ? rankSettings(settings) : settings;
  const auto draw = [&](const RenderSettings& s) { return renderer.render(scene, camera, s); };
  FrameStats stats = draw(drawn);
  // Loading the nodes is seconds of host work, in which GPU clocks fall to idle, so a frame that is one
  // resident pass is timed again with settled clocks, as the point methods are; its loading figures stay
  // the first frame's. A frame drawn in passes streams every time and keeps its one timing (its clocks are
  // reported unsettled); a software device is always settled.
  bool settled = !settlesClocks(context);
  if (stats.lod && stats.lod->passes == 1 && settleClocksWith(context, drawn, draw)) {
    const std::optional<lod::LodStats> loaded = stats.lod;
    stats = timeSettled(context, drawn, draw, settled);
    stats.lod = loaded;
    warnUnsettled(settled, stats.medianMs, stats.minMs);
  }
  std::vector<uint32_t> pixels;
  if (distributed) {
    if (context.validationErrors() > 0)
      throw InternalError("the Vulkan validation layer reported " +
                          std::to_string(context.validationErrors()) + " error(s), above");
    pixels = compositesInSteps(settings.method.info())
                 ? compositeHqsFrame(
                       renderer, [&](const RenderSettings& s) { return renderer.render(scene, camera, s); },
                       settings, stats, composite)
                 : compositeFrame(context, renderer, camera, settings, 0, stats, composite);
    stats.medianMs = composite.renderMs; // the frame is done when the slowest rank is
    stats.points = composite.points;
    stats.post = composite.post;
    if (!mpi::Job::get().root()) {
      mpi::Job::get().close();
      return 0;
    }
  } else {
    pixels = renderer.image();
    if (annotations) drawOverlay(renderer, camera, scene.bounds(), *annotations, pixels);
  }
  finishImage(
      a, context, pixels,
      [&] {
        nlohmann::json j = octreeJson(context, settings, octree, colors, stats, camera, a, pixels);
        j["clocks_settled"] = settled;
        if (distributed) j["mpi"] = compositeJson(composite); // batch and LOD counts are rank 0's
        if (!a.pick.empty()) {
          const PixelPos pixel = parsePick(a.pick, a.width, a.height);
          // The point in the lod pass's visibility buffer, its node read from the source.
          j["pick"] = pointrast::pickJson(renderer, scene, pixel.x, pixel.y);
        }
        return j;
      },
      [&] {
        std::printf("%s: %s of %s points, %ux%u, %s: %.3f ms median GPU time over %u frames (%.3f..%.3f), "
                    "%s points/s\n",
                    a.output.c_str(), humanCount(double(stats.points)).c_str(),
                    humanCount(double(octree.pointCount)).c_str(), a.width, a.height,
                    methodName(settings.method), stats.medianMs, stats.frames, stats.minMs, stats.maxMs,
                    humanCount(perSecond(stats.points, stats.medianMs)).c_str());
        printLodStats(*stats.lod, *stats.batch);
        if (stats.post) printPostStats(settings.post, *stats.post);
        if (distributed) printCompositeSummary(composite);
      });
  if (distributed) mpi::Job::get().close();
  return 0;
}

// The point-method options of the command line, checked before anything is read.
RenderSettings pointSettings(const RenderArgs& a) {
  if (!a.billboard.empty() || a.conservative)
    throw InputError("--billboard and --conservative apply to the sphere methods (" + billboardMethodNames() +
                     ")");
  if (a.meshlet || a.taskCull)
    throw InputError("--meshlet and --task-cull apply to sphere-mesh-points and sphere-mesh-tris");
  if (a.method.rfind("sphere-", 0) == 0) parseSphereMethod(a.method); // throws, naming the sphere methods
  if (isParticleSceneName(a.input) || std::filesystem::path(a.input).extension() == ".mmpld")
    throw InputError(a.input + " holds particles: draw them with a sphere method (--method sphere-compute)");
  RenderSettings settings;
  settings.method = parseMethod(a.method);
  settings.depth = parseDepthMode(a.depth);
  settings.precision = parsePrecision(a.precision);
  const SceneLayout layout = settings.method.info().layout;
  if (settings.precision != 0 && layout != SceneLayout::Batched && layout != SceneLayout::Octree)
    throw InputError("--precision applies to the batch and LOD methods (" +
                     methodNamesReading(SceneLayout::Batched) + ", " +
                     methodNamesReading(SceneLayout::Octree) + ")");
  if (a.eyes.stereo && layout != SceneLayout::Batched && layout != SceneLayout::Octree)
    throw InputError("--stereo draws both eyes in one pass with the batch and LOD methods (" +
                     methodNamesReading(SceneLayout::Batched) + ", " +
                     methodNamesReading(SceneLayout::Octree) + ")" +
                     (a.methodGiven ? ", not " + a.method
                                    : ": name one with --method (batch-prefetch for a cloud, lod for an octree)"));
  if (a.eyes.stereo && !a.path.path.empty())
    throw InputError("--stereo renders one frame with -o, not a camera path");
  settings.background = parseRgb(a.background, "--background");
  settings.frames = a.frames;
  settings.filter = renderFilter(a.filter);
  if (!a.pick.empty() && (a.eyes.stereo || !a.path.path.empty() || !a.json))
    throw InputError("--pick reports the point at a pixel of a mono image, in --json output (not with "
                     "--stereo or --path)");
  if (!a.pick.empty()) parsePick(a.pick, a.width, a.height);
  settings.captureWords = settings.captureWords || !a.pick.empty(); // the word at the pixel
  if (layout == SceneLayout::Octree) return settings; // runRenderOctree checks the octree's own options
  if (a.eyes.foveated || a.eyes.foveaRadius || a.eyes.foveaPeriphery)
    throw InputError("--foveated applies to the LOD methods (" + methodNamesReading(SceneLayout::Octree) +
                     "), which choose octree nodes by their size on screen");
  if (a.lod.given)
    throw InputError("--min-node-px, --point-budget and --gpu-memory apply to the LOD methods (" +
                     methodNamesReading(SceneLayout::Octree) + ")");
  settings.post = postSettings(a.look);
  settings.stereo = stereoSettings(a.eyes);
  if (settings.post.enabled() && settings.method.info().output == MethodOutput::ColorOnly)
    throw InputError("--point-size, --dilate and --edl need a compute method; " + a.method +
                     " keeps no depth per pixel to work on");
  if (a.parts == 0) throw InputError("--parts must be at least 1");
  return settings;
}

// --parts N: N separately uploaded scenes drawn into one framebuffer; they must give the same image as one
// upload (the atomic min does not care which dispatch a point came from).
std::vector<std::unique_ptr<GpuScene>> uploadParts(gpu::Context& context, const PointCloud& cloud,
                                                   SceneLayout layout,
                                                   const std::optional<DisplayColorMode>& colors,
                                                   const RenderArgs& a) {
  const uint64_t perPart = (cloud.size() + a.parts - 1) / a.parts;
  if (layout == SceneLayout::Batched && perPart > 0) {
    // Said before uploading: the batch methods address 64 parts of a frame (4.29 billion points).
    const uint64_t capacity =
        partCapacity(layout, 0, std::min(context.maxAllocationSize(), context.maxBufferSize()));
    const uint64_t parts = capacity ? uint64_t(a.parts) * ((perPart + capacity - 1) / capacity) : 0;
    if (parts > shared::kMaxVisibilityParts)
      throw InputError(cloud.source + " needs " + std::to_string(parts) +
                       " parts on this device; the batch methods draw at most " +
                       std::to_string(shared::kMaxVisibilityParts) + " (4.29 billion points) per frame");
  }
  std::vector<std::unique_ptr<GpuScene>> scenes;
  for (uint32_t p = 0; p < a.parts; ++p) {
    UploadOptions upload;
    upload.first = uint64_t(p) * perPart;
    upload.count = perPart;
    upload.layout = layout;
    upload.progress = !a.quiet;
    upload.colors = colors;
    upload.filter = pointFilter(a.filter); // a highlight tints the colors
    scenes.push_back(std::make_unique<GpuScene>(context, cloud, upload));
  }
  return scenes;
}

nlohmann::json pointJson(const gpu::Context& context, const RenderSettings& settings, const PointCloud& cloud,
                         Order order, const std::optional<DisplayColorMode>& colors, const FrameStats& stats,
                         const Camera& camera, const RenderArgs& a, const std::vector<uint32_t>& pixels) {
  nlohmann::json j;
  j["device"] = context.info().name;
  j["device_type"] = context.info().typeName;
  j["method"] = methodName(settings.method);
  j["depth"] = depthModeName(settings.depth);
  j["input"] = cloud.source;
  j["points"] = stats.points;
  j["order"] = orderName(order);
  addTimes(j, a, stats.frames, stats.medianMs, stats.minMs, stats.maxMs);
  j["points_per_second"] = perSecond(stats.points, stats.medianMs);
  j["parts"] = a.parts;
  if (stats.batch) {
    j["precision"] = a.precision;
    j["batch_stats"] = report::batchStatsJson(*stats.batch);
  }
  if (colors) j["color"] = colorSourceName(colors->source);
  if (a.eyes.stereo) j["stereo"] = stereoJson(a, settings.stereo, camera);
  if (stats.post) j["post"] = postJson(settings.post, *stats.post);
  j["camera"] = describeCamera(camera);
  j["image_hash"] = hashText(pixels);
  j["output"] = outputJson(a);
  return j;
}

void printPointSummary(const RenderArgs& a, const RenderSettings& settings, const FrameStats& stats) {
  std::printf("%s: %s points, %ux%u, %s: %.3f ms median GPU time over %u frames (%.3f..%.3f), %s points/s\n",
              a.output.c_str(), humanCount(double(stats.points)).c_str(), a.width, a.height,
              methodName(settings.method), stats.medianMs, stats.frames, stats.minMs, stats.maxMs,
              humanCount(perSecond(stats.points, stats.medianMs)).c_str());
  if (stats.batch) {
    const BatchStats& b = *stats.batch;
    std::printf("  batches: %llu processed, %llu rendered; points: %s processed (1/2/3 words: %s/%s/%s), "
                "%s rendered\n",
                (unsigned long long)b.batchesProcessed, (unsigned long long)b.batchesRendered,
                humanCount(double(b.pointsProcessed)).c_str(), humanCount(double(b.pointsByWords[0])).c_str(),
                humanCount(double(b.pointsByWords[1])).c_str(),
                humanCount(double(b.pointsByWords[2])).c_str(), humanCount(double(b.pointsRendered)).c_str());
    if (settings.method == pointMethod("batch-hqs"))
      std::printf("  blended: %s points; %llu dense batches drawn in one pass (%llu drawn again, %s points "
                  "blended again)\n",
                  humanCount(double(b.pointsBlended)).c_str(), (unsigned long long)b.batchesDense,
                  (unsigned long long)b.batchesRedrawn, humanCount(double(b.pointsTakenBack)).c_str());
  }
  if (stats.post)
    std::printf(
        "  resolve stage: point size %.3f ms, dilation %.3f ms, compose%s %.3f ms (median GPU time)\n",
        stats.post->splatMs, stats.post->dilateMs, settings.post.edlStrength > 0 ? " + EDL" : "",
        stats.post->composeMs);
}

// The input of a render: a generated scene carries its classes when a class filter or the classification
// colors need them.
InputSpec renderInputSpec(const RenderArgs& a, const RenderSettings& settings) {
  InputSpec spec = inputSpec(a.input, a.points, a.seed, a.order, a.quiet);
  spec.classification = settings.filter.classes.has_value() || a.look.color == "classification";
  return spec;
}

// A rank of `mpirun -np N pointrast render` (docs/mpi.md): its share of the points drawn on its device,
// the frame composited on rank 0, which alone resolves, writes and reports it.
int runRenderDistributed(const RenderArgs& a, const RenderSettings& settings) {
  mpi::Job& job = mpi::Job::get();
  checkDistributed(settings, !a.path.path.empty(), false);
  const InputSpec spec = renderInputSpec(a, settings);
  gpu::Context context(contextOptions(a));
  CompositeStats composite;
  composite.devices = announceRanks(context, a.quiet);
  const PointCloud cloud = loadShare(spec);
  const std::optional<DisplayColorMode> chosen = colorMode(a, cloud);
  const DisplayColorMode colors = agreeColors(chosen ? *chosen : displayColorMode(cloud));
  // Rank 0's camera for every rank: an overview is framed from a sample of its share.
  Camera camera = renderCamera(a, cloud.bounds, cloud.source, framingSample(cloud));
  job.broadcast(&camera, sizeof camera);
  Renderer renderer(context, a.width, a.height, a.eyes.stereo ? 2 : 1);
  const auto scenes = uploadParts(context, cloud, settings.method.info().layout, colors, a);
  std::vector<const GpuScene*> drawn;
  for (const auto& scene : scenes)
    drawn.push_back(scene.get());
  RenderSettings rank = rankSettings(settings);
  if (rank.depth == DepthMode::Int40 && rank.depthScale <= 0) rank.depthScale = int40ScaleOf(drawn, camera);
  settleClocksWith(context, rank, [&](const RenderSettings& s) { return renderer.render(drawn, camera, s); });
  bool settled = true;
  FrameStats stats = timeSettled(
      context, rank, [&](const RenderSettings& s) { return renderer.render(drawn, camera, s); }, settled);
  if (context.validationErrors() > 0)
    throw InternalError("the Vulkan validation layer reported " + std::to_string(context.validationErrors()) +
                        " error(s), above");
  const std::vector<uint32_t> pixels =
      compositesInSteps(settings.method.info())
          ? compositeHqsFrame(renderer, drawn, camera, settings, stats, composite)
          : compositeFrame(context, renderer, camera, settings, rank.depthScale, stats, composite);
  if (job.root()) {
    stats.medianMs = composite.renderMs; // the frame is done when the slowest rank is
    stats.points = composite.points;
    stats.batch.reset(); // counted per rank; the JSON would show rank 0's alone
    stats.post = composite.post;
    const std::optional<DisplayColorMode> named = chosen ? std::optional(colors) : std::nullopt;
    finishImage(
        a, context, pixels,
        [&] {
          nlohmann::json j = pointJson(context, settings, cloud, spec.order, named, stats, camera, a, pixels);
          j["clocks_settled"] = settled;
          j["mpi"] = compositeJson(composite);
          return j;
        },
        [&] {
          printPointSummary(a, settings, stats);
          printCompositeSummary(composite);
        });
  }
  job.close();
  return 0;
}

// --annotations: read before the device starts, for the methods that draw a loaded cloud into one mono
// image with a depth per pixel; the frame then keeps its canonical words for the overlay's depth test.
std::optional<Annotations> overlayAnnotations(const RenderArgs& a, RenderSettings& settings) {
  if (a.annotations.empty()) return std::nullopt;
  const MethodInfo& info = settings.method.info();
  const bool octree = info.layout == SceneLayout::Octree;
  if (a.eyes.stereo) throw InputError("--annotations draws over a mono image, not --stereo");
  // The resolve stage leaves float-depth words for any method (an octree's settings get it later).
  const bool resolved = (octree ? postSettings(a.look) : settings.post).enabled();
  if (!resolved && !hasCanonicalWords(info))
    throw InputError("--annotations needs the depth of each pixel, which " + a.method +
                     " does not keep; use a closest-point method (" + (octree ? "lod" : "atomicmin") +
                     ") or add --point-size 1.5");
  if (!resolved && settings.depth == DepthMode::Int40)
    throw InputError("--annotations reads float depths: leave --depth at float");
  settings.captureWords = true;
  return io::loadAnnotations(a.annotations);
}

// --pick: the point the last frame drew at the pixel, from its canonical word (render/pick.h).
nlohmann::json pickAt(Renderer& renderer, const PointCloud& cloud, const std::optional<DisplayColorMode>& colors,
                      const RenderSettings& settings, const Camera& camera, const RenderArgs& a) {
  const PixelPos pixel = parsePick(a.pick, a.width, a.height);
  if (!hasCanonicalWords(methodInfo(settings.method)) && !settings.post.enabled()) {
    nlohmann::json j;
    j["pixel"] = {pixel.x, pixel.y};
    j["point"] = std::string("unavailable: ") + a.method + " keeps no depth per pixel to pick from";
    return j;
  }
  const uint64_t word = renderer.framebufferWords(pixel.x, pixel.y, 1, 1)[0];
  PickRequest request;
  request.cloud = &cloud;
  request.colors = colors ? *colors : displayColorMode(cloud);
  request.filter = settings.filter;
  request.camera = camera;
  request.width = a.width;
  request.height = a.height;
  request.depth = settings.post.enabled() ? DepthMode::Float : settings.depth;
  return pickJson(cloud, pixel, word == shared::kEmptyPixel, pickPoint(request, pixel.x, pixel.y, word));
}

int runRender(const RenderArgs& a) {
  Progress::setEnabled(!a.quiet); // progress goes to stderr, so it does not disturb --json on stdout
  checkCommonArgs(a);
  if (distributedRun() && isSphereMethodName(a.method)) checkDistributed({}, false, true);
  if (isSphereMethodName(a.method)) return runRenderSpheres(a);
  RenderSettings settings = pointSettings(a);
  const std::optional<Annotations> annotations = overlayAnnotations(a, settings);
  if (distributedRun() && annotations)
    throw InputError("--annotations draws over the frame of one process; under mpirun render draws without it");
  if (settings.method.info().layout == SceneLayout::Octree) return runRenderOctree(a, settings, annotations);
  if (distributedRun()) return runRenderDistributed(a, settings);
  view::CameraPath cameraPath;
  if (!a.path.path.empty()) cameraPath = loadPathForRender(a.path, a.width, a.height);
  const InputSpec spec = renderInputSpec(a, settings);

  // The header's count before the device starts, the device's memory before the read.
  const std::optional<uint64_t> stated = statedPoints(spec);
  gpu::Context context(contextOptions(a));
  std::string why;
  if (stated && !sceneFits(context, settings.method.info().layout, *stated, &why))
    throw UnsupportedError((a.input.empty() ? kDemoScene : a.input) + ": " + why);
  PointCloud cloud = loadInput(spec);
  filterLoadedCloud(cloud, settings.filter);
  const std::optional<DisplayColorMode> colors = colorMode(a, cloud);
  const Camera camera = renderCamera(a, cloud.bounds, cloud.source, framingSample(cloud));
  Renderer renderer(context, a.width, a.height, a.eyes.stereo ? 2 : 1);
  const auto scenes = uploadParts(context, cloud, settings.method.info().layout, colors, a);
  std::vector<const GpuScene*> drawn;
  for (const auto& scene : scenes)
    drawn.push_back(scene.get());
  if (!a.path.path.empty()) {
    if (cameraPath.empty()) cameraPath = view::orbitPath(camera);
    view::FrameOverlay overlay;
    if (annotations)
      overlay = [&](const Camera& c, std::vector<uint32_t>& image) {
        drawOverlay(renderer, c, cloud.bounds, *annotations, image);
      };
    return renderCameraPath(context, renderer, drawn, settings, cameraPath, a.path, a.json, a.quiet, overlay);
  }
  settleClocksWith(context, settings, [&](const RenderSettings& s) { return renderer.render(drawn, camera, s); });
  bool settled = true;
  const FrameStats stats = timeSettled(
      context, settings, [&](const RenderSettings& s) { return renderer.render(drawn, camera, s); }, settled);
  warnUnsettled(settled, stats.medianMs, stats.minMs);
  std::vector<uint32_t> pixels = renderer.image();
  if (annotations) drawOverlay(renderer, camera, cloud.bounds, *annotations, pixels);
  finishImage(
      a, context, pixels,
      [&] {
        nlohmann::json j = pointJson(context, settings, cloud, spec.order, colors, stats, camera, a, pixels);
        j["clocks_settled"] = settled;
        if (!a.pick.empty()) j["pick"] = pickAt(renderer, cloud, colors, settings, camera, a);
        return j;
      },
      [&] { printPointSummary(a, settings, stats); });
  return 0;
}

// "  name  description" per point method, from the method table.
std::string methodList() {
  std::string list;
  for (Method m : allMethods()) {
    std::string name = m.name();
    list += "  " + name + std::string(name.size() < 16 ? 16 - name.size() : 1, ' ') + m.info().help + "\n";
  }
  return list;
}

// The same for the sphere methods.
std::string sphereMethodList() {
  std::string list;
  for (const SphereMethodInfo& m : sphereMethodTable()) {
    std::string name = m.name;
    list += "  " + name + std::string(name.size() < 20 ? 20 - name.size() : 1, ' ') + m.description + "\n";
  }
  return list;
}

// `render --help`'s text after the options: the input, the camera, the methods from their tables, and
// examples.
std::string renderFooter() {
  const std::string text =
      "\nWithout FILE, renders the built-in demo scene (terrain, 1 M points). FILE may also be a scene name\n"
      "(terrain, tls) generated with --points and --seed.\n"
      "Without --eye the camera is an overview: it looks at the cloud face on to its longer horizontal side\n"
      "(from the south, or the west), 35 degrees above the horizon, z up, as close as keeps a sample of its\n"
      "points (an octree's root node) in the image, centered.\n"
      "Coordinates of --eye/--target are in the file's own units (after LAS scale/offset).\n"
      "The GPU time is the median over --frames frames of clear + draw + resolve, from timestamp queries.\n\n"
      "Point methods (--method):\n" +
      methodList() +
      "\nExamples:\n"
      "  pointrast render -o demo.png\n"
      "  pointrast render autzen.las -o a.png --json\n"
      "  pointrast render autzen.las -o a.png --eye 636000,848900,700 --target 636600,849200,450\n"
      "  pointrast render terrain --points 100M --order morton -o t.png --frames 50\n"
      "  pointrast render terrain --points 1G --order morton --method batch-prefetch -o t.png --json\n"
      "  pointrast render autzen.las -o a.png --color classification --point-size 3 --edl\n"
      "  pointrast render autzen.las -o a.png --color elevation --dilate 2\n"
      "  pointrast render autzen.las --path path.json --video fly.mp4 --fps 60 --width 3840 --height 2160\n"
      "Stereo (--stereo, batch and LOD methods): the eyes sit --ipd apart around --eye, look in parallel\n"
      "and their frusta are shifted so that the plane at --convergence lies at the same pixels in both\n"
      "images (nearer points stand out of the screen). --width and --height are each eye's.\n"
      "  pointrast render autzen.las --method batch-prefetch --stereo -o sbs.png\n"
      "  pointrast render cloud_lod --method lod-hqs --stereo --ipd 0.064 --convergence inf --foveated \\\n"
      "      --dilate 1 --width 2478 --height 2740 -o vr.png\n"
      "Spheres (particles): a sphere method with an MMPLD file, a particle scene (" +
      std::string(kParticleSceneNames) + ") or points and --radius.\nSphere methods (--method):\n" +
      sphereMethodList() + "The pipelines that rasterize billboards (" + billboardMethodNames() +
      ") take --billboard screen|camera\n"
      "and --conservative (overestimating conservative rasterization, where the device has it); the image "
      "is the same,\nonly the fragments spent on it differ.\n"
      "  pointrast render particles-drops --points 10M --method sphere-compute -o d.png\n"
      "  pointrast render md.mmpld --method sphere-compute --layout soa8 -o md.png --json\n"
      "  pointrast render particles-laser --points 10M --method sphere-strip --billboard camera -o l.png";
  return text;
}

// Options bind to members of the RenderArgs that the command's closure keeps alive with the app.
// The input, the image and the camera.
void addViewOptions(CLI::App& cmd, RenderArgs& a) {
  cmd.add_option("FILE", a.input,
                 "Point cloud file (" + io::formatList(io::FormatUse::Cloud) + "), particle file (" +
                     io::formatList(io::FormatUse::Particles) + ") or a scene name (terrain, tls)");
  cmd.add_option("-o,--output", a.output, "PNG to write (required unless --path)");
  cmd.add_option("--width", a.width, "Image width in pixels")->capture_default_str();
  cmd.add_option("--height", a.height, "Image height in pixels")->capture_default_str();
  cmd.add_option("--eye", a.eye, "Camera position x,y,z (default: overview)");
  cmd.add_option("--target", a.target, "Point looked at x,y,z (default: center of the bounds)");
  cmd.add_option("--up", a.up, "Up direction x,y,z")->capture_default_str();
  cmd.add_option("--fov", a.fov, "Vertical field of view in degrees")->capture_default_str();
  cmd.add_option("--near", a.nearW, "Drop points at linear depth <= near (0: 1e-5 x bounds diagonal)");
  cmd.add_option("--background", a.background, "Background color r,g,b (0..255)")->capture_default_str();
}

// The method, its variants, the level of detail and what is timed.
void addMethodOptions(CLI::App& cmd, RenderArgs& a) {
  cmd.add_option("--order", a.order, "Vertex order: original, morton, shuffled, shuffled-morton")
      ->capture_default_str();
  cmd.add_option(
         "--method", a.method,
         "Rasterization method, e.g. atomicmin (compute) or hw-points (the hardware GL_POINTS baseline); "
         "an unknown name lists them all")
      ->capture_default_str()
      ->each([&a](const std::string&) { a.methodGiven = true; });
  cmd.add_option("--depth", a.depth,
                 "Depth encoding of the atomic methods: float (32-bit linear depth) or int40 (40-bit integer "
                 "computed in double precision)")
      ->capture_default_str();
  cmd.add_option("--precision", a.precision,
                 "Batch methods: coordinate words per point, adaptive (the fewest that keep each batch's "
                 "error under half a pixel) or 1, 2, 3 (3 = full 30-bit precision)")
      ->capture_default_str();
  addLodOptions(cmd, a.lod);
  cmd.add_option("--seed", a.seed, "Seed for generated scenes and shuffled orders")->capture_default_str();
  cmd.add_option("--points", a.points, "Points of a generated scene (e.g. 1M, 1.2G)")->capture_default_str();
  cmd.add_option("--frames", a.frames, "Timed frames; the median GPU time is reported")
      ->capture_default_str();
  cmd.add_option("--parts", a.parts, "Upload the cloud as N separate scenes drawn into one framebuffer")
      ->capture_default_str();
}

// What the sphere methods alone read.
void addSphereOptions(CLI::App& cmd, RenderArgs& a) {
  cmd.add_option("--radius", a.radius,
                 "Sphere methods: radius of points drawn as spheres, or replacing an MMPLD file's radii");
  cmd.add_option("--frame", a.frame, "Sphere methods: the MMPLD frame to draw")->capture_default_str();
  cmd.add_option("--layout", a.layout, "Sphere methods: GPU particle layout soa8, vec4x2, aos, xyz, or auto")
      ->capture_default_str();
  cmd.add_option("--billboard", a.billboard,
                 "Sphere pipelines that rasterize billboards: screen (the tight screen-space box of the "
                 "projected sphere, the default) or camera (a camera-aligned square, side 2r enlarged to "
                 "cover the sphere under perspective)");
  cmd.add_flag("--conservative", a.conservative,
               "Sphere pipelines that rasterize billboards: overestimating conservative rasterization "
               "(VK_EXT_conservative_rasterization; refused where the device lacks it)");
  cmd.add_option("--meshlet", a.meshlet,
                 "sphere-mesh-points, sphere-mesh-tris: spheres per mesh workgroup, 31 (default) or 15");
  cmd.add_flag("--task-cull", a.taskCull,
               "sphere-mesh-points, sphere-mesh-tris: a task shader culls spheres outside the view first "
               "and launches mesh workgroups only for the rest");
}


} // namespace

Command addRender(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Render a point cloud file or a generated scene to a PNG");
  cmd->footer(renderFooter());
  addViewOptions(*cmd, *a);
  addMethodOptions(*cmd, *a);
  addSphereOptions(*cmd, *a);
  addLookOptions(*cmd, a->look);
  addFilterOptions(*cmd, a->filter);
  cmd->add_option("--pick", a->pick,
                  "With --json: report the point drawn at pixel X,Y (0,0 at the top left) with its attributes");
  addStereoOptions(*cmd, a->eyes);
  cmd->add_option("--device", a->device, "Vulkan device index (see `pointrast info --devices`)");
  cmd->add_flag("--json", a->json, "Print one JSON object with the result");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress or device lines");
  addPathOptions(*cmd, a->path);
  cmd->add_option("--annotations", a->annotations,
                  "Measurements, labels and clip volumes (a JSON file, docs/tools.md) drawn over the image, "
                  "hidden where points are closer");
  return [a] { return runRender(*a); };
}

} // namespace pointrast::app
