// pointrast render [FILE|SCENE] -o OUT.png ...
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "base/text.h"
#include "bench/lod_report.h"
#include "bench/report.h"
#include "cli_util.h"
#include "cloud/attribute_colors.h"
#include "cloud/generate.h"
#include "cloud/particles_generate.h"
#include "commands.h"
#include "gpu/context.h"
#include "gpu/shared_types.h"
#include "input.h"
#include "io/format_table.h"
#include "io/writer.h"
#include "render/lod/lod_scene.h"
#include "render/renderer.h"
#include "render/spheres/sphere_renderer.h"
#include "render_path.h"

namespace pointrast::app {

namespace {

struct RenderArgs {
  std::string input, output, eye, target, up = "0,0,1", background = "0,0,0", order = "original";
  std::string method = "atomicmin", points = "1M", depth = "float";
  std::string precision = "adaptive"; // batch methods
  double minNodePx = 100;             // LOD methods
  std::string pointBudget = "0";      // LOD methods; 0: no limit
  std::string gpuMemory;              // LOD methods: node cache budget; empty: half the device
  bool lodOptionsGiven = false;       // one of the three above was given
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
  // Point methods: coloring and the resolve stage.
  std::string color = "auto", colorRange;
  float pointSize = 1, pointSizeMax = 16;
  std::string pointShape = "square", pointSizeMode = "fixed";
  uint32_t dilate = 0;
  bool edl = false;
  std::optional<float> edlStrength, edlRadius;
};

// Whether any option of the resolve stage or of coloring was given (the sphere methods take none).
bool postOrColorGiven(const RenderArgs& a) {
  return a.color != "auto" || !a.colorRange.empty() || a.pointSize != 1 || a.pointSizeMax != 16 ||
         a.pointShape != "square" || a.pointSizeMode != "fixed" || a.dilate != 0 || a.edl || a.edlStrength ||
         a.edlRadius;
}

// --point-size, --point-shape, --point-size-mode, --point-size-max, --dilate, --edl*.
PostSettings postSettings(const RenderArgs& a) {
  PostSettings post;
  post.pointSize = a.pointSize;
  post.shape = parsePointShape(a.pointShape);
  post.sizeMode = parsePointSizeMode(a.pointSizeMode);
  post.maxPointSize = a.pointSizeMax;
  post.dilate = a.dilate;
  // --edl-strength or --edl-radius alone turn eye-dome lighting on, with Potree's defaults for the other.
  if (a.edl || a.edlStrength || a.edlRadius) {
    post.edlStrength = a.edlStrength.value_or(1.0f);
    post.edlRadius = a.edlRadius.value_or(post.edlRadius);
  }
  validatePostSettings(post);
  return post;
}

// --color and --color-range: nullopt for auto (displayColorMode's choice).
std::optional<DisplayColorMode> colorMode(const RenderArgs& a, const PointCloud& cloud) {
  if (a.color == "auto") {
    if (!a.colorRange.empty()) throw InputError("--color-range applies to --color intensity and elevation");
    return std::nullopt;
  }
  DisplayColorMode::Source source = parseColorSource(a.color);
  std::optional<ColorRange> range;
  if (!a.colorRange.empty()) {
    if (source != DisplayColorMode::Source::Intensity && source != DisplayColorMode::Source::Elevation)
      throw InputError("--color-range applies to --color intensity and elevation, not " + a.color);
    auto [lo, hi] = parseRange(a.colorRange, "--color-range");
    range = ColorRange{lo, hi};
  }
  return displayColorMode(cloud, source, range);
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

// The sphere methods (--method sphere-*): particles from an MMPLD file, a particle scene, or points drawn
// as spheres of --radius, through the SphereRenderer.
int runRenderSpheres(const RenderArgs& a) {
  SphereSettings settings;
  settings.method = parseSphereMethod(a.method);
  settings.background = parseRgb(a.background, "--background");
  settings.frames = a.frames;
  if (a.frames == 0) throw InputError("--frames must be at least 1");
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
  bool mesh = settings.method == SphereMethod::MeshPoints || settings.method == SphereMethod::MeshTriangles;
  if ((a.meshlet || a.taskCull) && !mesh)
    throw InputError("--meshlet and --task-cull apply to sphere-mesh-points and sphere-mesh-tris, not to " +
                     a.method);
  settings.meshlet = a.meshlet.value_or(shared::kSphereMeshletLarge);
  settings.taskCull = a.taskCull;
  if (settings.meshlet != shared::kSphereMeshletLarge && settings.meshlet != shared::kSphereMeshletSmall)
    throw InputError("--meshlet takes " + std::to_string(shared::kSphereMeshletLarge) + " or " +
                     std::to_string(shared::kSphereMeshletSmall) + " (spheres per mesh workgroup), not " +
                     std::to_string(settings.meshlet));
  if (std::filesystem::path(a.output).extension() != ".png")
    throw InputError("-o " + a.output + ": the output must be a .png file");
  ParticleUploadOptions upload;
  upload.progress = !a.quiet;
  if (a.layout != "auto") upload.layout = parseParticleLayout(a.layout);
  if (!a.target.empty() && a.eye.empty()) throw InputError("--target needs --eye");

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
  gpu::ContextOptions contextOptions;
  contextOptions.deviceIndex = a.device;
  contextOptions.announce = !a.quiet;
  gpu::Context context(contextOptions);
  std::string why;
  if (stated && !particlesFit(context, upload.layout, *stated, &why))
    throw UnsupportedError((a.input.empty() ? kDemoParticleScene : a.input) + ": " + why);
  if (!SphereRenderer::supports(context, settings, &why)) throw UnsupportedError(why); // before the read
  ParticleSet set = loadParticles(spec);
  if (upload.layout && !layoutHolds(*upload.layout, set, &why)) throw InputError(why);
  Bounds bounds = sphereBounds(set);
  Camera camera = overviewCamera(bounds, double(a.width) / double(a.height), a.fov);
  if (!a.eye.empty()) {
    camera.eye = parseVec3(a.eye, "--eye");
    camera.target = a.target.empty() ? bounds.center() : parseVec3(a.target, "--target");
    camera.up = parseVec3(a.up, "--up");
  }
  camera.nearW = a.nearW;
  validateCamera(camera);

  SphereRenderer renderer(context, a.width, a.height);
  GpuParticles particles(context, set, upload);
  SphereStats stats = renderer.render(particles, camera, settings);
  std::vector<uint32_t> pixels = renderer.image();
  if (context.validationErrors() > 0)
    throw InputError("the Vulkan validation layer reported " + std::to_string(context.validationErrors()) +
                     " error(s)");
  io::writePng(a.output, a.width, a.height, pixels.data());
  double perSecond = stats.medianMs > 0 ? double(stats.particles) / (stats.medianMs * 1e-3) : 0.0;
  if (a.json) {
    nlohmann::json j;
    j["device"] = context.info().name;
    j["device_type"] = context.info().typeName;
    j["method"] = sphereMethodName(settings.method);
    j["layout"] = particleLayoutName(particles.layout());
    if (sphereMethodTakesBillboards(settings.method)) {
      j["billboard"] = sphereBillboardName(settings.billboard);
      j["conservative"] = settings.conservative;
    }
    if (mesh) {
      j["meshlet"] = settings.meshlet;
      j["task_cull"] = settings.taskCull;
    }
    if (settings.method == SphereMethod::RayTracing) j["build_ms"] = stats.buildMs;
    j["input"] = set.source;
    j["particles"] = stats.particles;
    j["width"] = a.width;
    j["height"] = a.height;
    j["frames"] = stats.frames;
    j["median_ms"] = stats.medianMs;
    j["min_ms"] = stats.minMs;
    j["max_ms"] = stats.maxMs;
    j["particles_per_second"] = perSecond;
    j["large_chunks"] = stats.largeChunks;
    j["spilled_spheres"] = stats.spilledSpheres;
    j["clamped_spheres"] = stats.clampedSpheres;
    j["camera"] = describeCamera(camera);
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx",
                  static_cast<unsigned long long>(imageHash(pixels.data(), pixels.size())));
    j["image_hash"] = hex;
    j["output"] = a.output;
    std::printf("%s\n", j.dump().c_str());
  } else if (!a.quiet) {
    std::printf("%s: %s particles (%s), %ux%u, %s: %.3f ms median GPU time over %u frames (%.3f..%.3f), %s "
                "particles/s\n",
                a.output.c_str(), humanCount(double(stats.particles)).c_str(),
                particleLayoutName(particles.layout()), a.width, a.height, sphereMethodName(settings.method),
                stats.medianMs, stats.frames, stats.minMs, stats.maxMs, humanCount(perSecond).c_str());
    if (settings.method == SphereMethod::RayTracing)
      std::printf("  acceleration structures built in %.3f ms of GPU time (not in the frame times)\n",
                  stats.buildMs);
  }
  return 0;
}

// The camera of the point methods: --eye/--target/--up/--fov/--near, or the overview of `bounds`.
Camera cameraFor(const RenderArgs& a, const Bounds& bounds) {
  if (!a.target.empty() && a.eye.empty()) throw InputError("--target needs --eye");
  Camera camera = overviewCamera(bounds, double(a.width) / double(a.height), a.fov);
  if (!a.eye.empty()) {
    camera.eye = parseVec3(a.eye, "--eye");
    camera.target = a.target.empty() ? bounds.center() : parseVec3(a.target, "--target");
    camera.up = parseVec3(a.up, "--up");
  }
  camera.nearW = a.nearW;
  validateCamera(camera);
  return camera;
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

// The LOD methods (--method lod, lod-hqs): an octree streamed through the node cache.
int runRenderOctree(const RenderArgs& a, RenderSettings settings) {
  if (!a.path.path.empty())
    throw InputError("--path renders the methods that draw a loaded cloud, not " + a.method + " (an octree)");
  if (a.order != "original" || a.parts != 1 || a.depth != "float")
    throw InputError("--order, --parts and --depth do not apply to " + a.method +
                     ", which draws an octree's nodes in their stored order");
  if (!(a.minNodePx >= 0)) throw InputError("--min-node-px must be 0 or more");
  settings.minNodePx = a.minNodePx;
  settings.pointBudget = parseCount(a.pointBudget, "--point-budget");
  settings.background = parseRgb(a.background, "--background");
  settings.frames = a.frames;
  if (a.frames == 0) throw InputError("--frames must be at least 1");
  if (std::filesystem::path(a.output).extension() != ".png")
    throw InputError("-o " + a.output + ": the output must be a .png file");
  if (a.width == 0 || a.height == 0) throw InputError("--width and --height must be at least 1");
  if (a.input.empty() || isSceneName(a.input))
    throw InputError((a.input.empty() ? std::string("the demo scene") : a.input) + " is a generated scene; " +
                     a.method + " draws octrees (" + io::formatList(io::FormatUse::Octree) +
                     "): build one with `pointrast lod FILE -o DIR`");
  lod::LodOptions options;
  if (!a.gpuMemory.empty()) options.gpuBytes = parseBytes(a.gpuMemory, "--gpu-memory");
  std::unique_ptr<lod::NodeSource> source = io::openNodeSource(a.input);
  const Camera camera =
      cameraFor(a, source->metadata().bounds.empty() ? source->metadata().cube : source->metadata().bounds);

  gpu::ContextOptions contextOptions;
  contextOptions.deviceIndex = a.device;
  contextOptions.announce = !a.quiet;
  gpu::Context context(contextOptions);
  std::string why;
  if (!Renderer::supports(context, settings.method, &why)) throw UnsupportedError(why);
  Renderer renderer(context, a.width, a.height);
  lod::LodScene octree(context, *source, options);
  FrameStats stats = renderer.render(octree, camera, settings);
  std::vector<uint32_t> pixels = renderer.image();
  if (context.validationErrors() > 0)
    throw InputError("the Vulkan validation layer reported " + std::to_string(context.validationErrors()) +
                     " error(s)");
  io::writePng(a.output, a.width, a.height, pixels.data());
  const double perSecond = stats.medianMs > 0 ? double(stats.points) / (stats.medianMs * 1e-3) : 0.0;
  if (a.json) {
    nlohmann::json j;
    j["device"] = context.info().name;
    j["device_type"] = context.info().typeName;
    j["method"] = methodName(settings.method);
    j["input"] = source->metadata().source;
    j["format"] = source->metadata().format;
    j["octree_points"] = source->metadata().pointCount;
    j["points"] = stats.points;
    j["width"] = a.width;
    j["height"] = a.height;
    j["frames"] = stats.frames;
    j["median_ms"] = stats.medianMs;
    j["min_ms"] = stats.minMs;
    j["max_ms"] = stats.maxMs;
    j["points_per_second"] = perSecond;
    j["precision"] = a.precision;
    j["min_node_px"] = settings.minNodePx;
    j["point_budget"] = settings.pointBudget;
    j["batch_stats"] = bench::batchStatsJson(*stats.batch);
    j["lod_stats"] = bench::lodStatsJson(*stats.lod);
    j["camera"] = describeCamera(camera);
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx",
                  static_cast<unsigned long long>(imageHash(pixels.data(), pixels.size())));
    j["image_hash"] = hex;
    j["output"] = a.output;
    std::printf("%s\n", j.dump().c_str());
  } else if (!a.quiet) {
    std::printf("%s: %s of %s points, %ux%u, %s: %.3f ms median GPU time over %u frames (%.3f..%.3f), %s "
                "points/s\n",
                a.output.c_str(), humanCount(double(stats.points)).c_str(),
                humanCount(double(source->metadata().pointCount)).c_str(), a.width, a.height,
                methodName(settings.method), stats.medianMs, stats.frames, stats.minMs, stats.maxMs,
                humanCount(perSecond).c_str());
    printLodStats(*stats.lod, *stats.batch);
  }
  return 0;
}

int runRender(const RenderArgs& a) {
  Progress::setEnabled(!a.quiet); // progress goes to stderr, so it does not disturb --json on stdout
  // -o is the single image; --path renders a camera path into --video or --frames-dir instead.
  bool pathMode = !a.path.path.empty();
  if (!pathMode && (!a.path.video.empty() || !a.path.framesDir.empty()))
    throw InputError("--video and --frames-dir need --path (a camera path)");
  if (pathMode == !a.output.empty())
    throw InputError(pathMode ? "--path replaces -o: give one of them" : "-o is required");
  if (pathMode && isSphereMethodName(a.method))
    throw InputError("--path renders the point methods, not " + a.method);
  if (isSphereMethodName(a.method)) return runRenderSpheres(a);
  if (!a.billboard.empty() || a.conservative)
    throw InputError("--billboard and --conservative apply to the sphere methods (" + billboardMethodNames() +
                     ")");
  if (a.meshlet || a.taskCull)
    throw InputError("--meshlet and --task-cull apply to sphere-mesh-points and sphere-mesh-tris");
  if (a.method.rfind("sphere-", 0) == 0) parseSphereMethod(a.method); // throws, naming the sphere methods
  if (isParticleSceneName(a.input) || std::filesystem::path(a.input).extension() == ".mmpld")
    throw InputError(a.input + " holds particles: draw them with a sphere method (--method sphere-compute)");
  InputSpec spec;
  spec.source = a.input;
  spec.points = parseCount(a.points, "--points");
  spec.seed = a.seed;
  spec.order = parseOrder(a.order);
  spec.progress = !a.quiet;
  RenderSettings settings;
  settings.method = parseMethod(a.method);
  settings.depth = parseDepthMode(a.depth);
  settings.precision = parsePrecision(a.precision);
  const SceneLayout layout = methodInfo(settings.method).layout;
  if (settings.precision != 0 && layout != SceneLayout::Batched && layout != SceneLayout::Octree)
    throw InputError("--precision applies to the batch and LOD methods (" +
                     methodNamesReading(SceneLayout::Batched) + ", " +
                     methodNamesReading(SceneLayout::Octree) + ")");
  if (layout == SceneLayout::Octree) return runRenderOctree(a, settings);
  if (a.lodOptionsGiven)
    throw InputError("--min-node-px, --point-budget and --gpu-memory apply to the LOD methods (" +
                     methodNamesReading(SceneLayout::Octree) + ")");
  settings.background = parseRgb(a.background, "--background");
  settings.post = postSettings(a);
  if (settings.post.enabled() && methodInfo(settings.method).output == MethodOutput::ColorOnly)
    throw InputError("--point-size, --dilate and --edl need a compute method; " + a.method +
                     " keeps no depth per pixel to work on");
  settings.frames = a.frames;
  if (a.frames == 0) throw InputError("--frames must be at least 1");
  if (a.parts == 0) throw InputError("--parts must be at least 1");
  if (!pathMode && std::filesystem::path(a.output).extension() != ".png")
    throw InputError("-o " + a.output + ": the output must be a .png file");
  if (a.width == 0 || a.height == 0) throw InputError("--width and --height must be at least 1");
  view::CameraPath cameraPath;
  if (pathMode) cameraPath = loadPathForRender(a.path, a.width, a.height);

  Camera camera;
  bool explicitCamera = !a.eye.empty();
  if (!a.target.empty() && !explicitCamera) throw InputError("--target needs --eye");
  if (explicitCamera) {
    camera.eye = parseVec3(a.eye, "--eye");
    camera.up = parseVec3(a.up, "--up");
    camera.fovY = a.fov;
    camera.nearW = a.nearW;
  }

  // As for spheres: the header's count before the device starts, the device's memory before the read.
  const std::optional<uint64_t> stated = statedPoints(spec);
  gpu::ContextOptions contextOptions;
  contextOptions.deviceIndex = a.device;
  contextOptions.announce = !a.quiet;
  gpu::Context context(contextOptions);
  std::string why;
  if (stated && !sceneFits(context, layout, *stated, &why))
    throw UnsupportedError((a.input.empty() ? kDemoScene : a.input) + ": " + why);
  PointCloud cloud = loadInput(spec);
  const std::optional<DisplayColorMode> colors = colorMode(a, cloud);
  double aspect = double(a.width) / double(a.height);
  if (explicitCamera) {
    camera.target = a.target.empty() ? cloud.bounds.center() : parseVec3(a.target, "--target");
  } else {
    camera = overviewCamera(cloud.bounds, aspect, a.fov);
    camera.nearW = a.nearW;
  }
  validateCamera(camera);

  Renderer renderer(context, a.width, a.height);

  // --parts N: N separately uploaded scenes drawn into one framebuffer; they must give the same image
  // as one upload (the atomic min does not care which dispatch a point came from).
  std::vector<std::unique_ptr<GpuScene>> scenes;
  uint64_t perPart = (cloud.size() + a.parts - 1) / a.parts;
  if (layout == SceneLayout::Batched && perPart > 0) {
    // Said before uploading: the batch methods address 64 parts of a frame (4.29 billion points).
    uint64_t capacity =
        partCapacity(layout, 0, std::min(context.maxAllocationSize(), context.maxBufferSize()));
    uint64_t parts = capacity ? uint64_t(a.parts) * ((perPart + capacity - 1) / capacity) : 0;
    if (parts > shared::kMaxVisibilityParts)
      throw InputError(cloud.source + " needs " + std::to_string(parts) +
                       " parts on this device; the batch methods "
                       "draw at most " +
                       std::to_string(shared::kMaxVisibilityParts) + " (4.29 billion points) per frame");
  }
  for (uint32_t p = 0; p < a.parts; ++p) {
    UploadOptions upload;
    upload.first = uint64_t(p) * perPart;
    upload.count = perPart;
    upload.layout = layout;
    upload.progress = !a.quiet;
    upload.colors = colors;
    scenes.push_back(std::make_unique<GpuScene>(context, cloud, upload));
  }
  std::vector<const GpuScene*> drawn;
  for (auto& s : scenes)
    drawn.push_back(s.get());
  if (pathMode && cameraPath.empty()) cameraPath = view::orbitPath(camera);
  if (pathMode)
    return renderCameraPath(context, renderer, drawn, settings, cameraPath, a.path, a.json, a.quiet);
  FrameStats stats = renderer.render(drawn, camera, settings);
  std::vector<uint32_t> pixels = renderer.image();
  io::writePng(a.output, a.width, a.height, pixels.data());
  uint64_t hash = imageHash(pixels.data(), pixels.size());

  if (context.validationErrors() > 0)
    throw InputError("the Vulkan validation layer reported " + std::to_string(context.validationErrors()) +
                     " error(s)");
  if (a.json) {
    nlohmann::json j;
    j["device"] = context.info().name;
    j["device_type"] = context.info().typeName;
    j["method"] = methodName(settings.method);
    j["depth"] = depthModeName(settings.depth);
    j["input"] = cloud.source;
    j["points"] = stats.points;
    j["order"] = orderName(spec.order);
    j["width"] = a.width;
    j["height"] = a.height;
    j["frames"] = stats.frames;
    j["median_ms"] = stats.medianMs;
    j["min_ms"] = stats.minMs;
    j["max_ms"] = stats.maxMs;
    j["points_per_second"] = stats.medianMs > 0 ? double(stats.points) / (stats.medianMs * 1e-3) : 0.0;
    j["parts"] = a.parts;
    if (stats.batch) {
      j["precision"] = a.precision;
      j["batch_stats"] = bench::batchStatsJson(*stats.batch);
    }
    if (colors) j["color"] = colorSourceName(colors->source);
    if (stats.post) j["post"] = postJson(settings.post, *stats.post);
    j["camera"] = describeCamera(camera);
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
    j["image_hash"] = hex;
    j["output"] = a.output;
    std::printf("%s\n", j.dump().c_str());
  } else if (!a.quiet) {
    std::printf(
        "%s: %s points, %ux%u, %s: %.3f ms median GPU time over %u frames (%.3f..%.3f), %s points/s\n",
        a.output.c_str(), humanCount(double(stats.points)).c_str(), a.width, a.height,
        methodName(settings.method), stats.medianMs, stats.frames, stats.minMs, stats.maxMs,
        humanCount(stats.medianMs > 0 ? double(stats.points) / (stats.medianMs * 1e-3) : 0).c_str());
    if (stats.batch) {
      const BatchStats& b = *stats.batch;
      std::printf(
          "  batches: %llu processed, %llu rendered; points: %s processed (1/2/3 words: %s/%s/%s), %s "
          "rendered\n",
          (unsigned long long)b.batchesProcessed, (unsigned long long)b.batchesRendered,
          humanCount(double(b.pointsProcessed)).c_str(), humanCount(double(b.pointsByWords[0])).c_str(),
          humanCount(double(b.pointsByWords[1])).c_str(), humanCount(double(b.pointsByWords[2])).c_str(),
          humanCount(double(b.pointsRendered)).c_str());
    }
    if (stats.post)
      std::printf(
          "  resolve stage: point size %.3f ms, dilation %.3f ms, compose%s %.3f ms (median GPU time)\n",
          stats.post->splatMs, stats.post->dilateMs, settings.post.edlStrength > 0 ? " + EDL" : "",
          stats.post->composeMs);
  }
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

} // namespace

Command addRender(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Render a point cloud file or a generated scene to a PNG");
  cmd->footer(
      "\nWithout FILE, renders the built-in demo scene (terrain, 1 M points). FILE may also be a scene name\n"
      "(terrain, tls) generated with --points and --seed.\n"
      "Without --eye the camera is an overview: it looks at the center of the bounds from the south-west,\n"
      "35 degrees above the horizon, z up, as close as keeps the whole bounding box in the image.\n"
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
      "Spheres (particles): a sphere method with an MMPLD file, a particle scene (" +
      std::string(kParticleSceneNames) + ") or points and --radius.\nSphere methods (--method):\n" +
      sphereMethodList() + "The pipelines that rasterize billboards (" + billboardMethodNames() +
      ") take --billboard screen|camera\n"
      "and --conservative (overestimating conservative rasterization, where the device has it); the image "
      "is the same,\nonly the fragments spent on it differ.\n"
      "  pointrast render particles-drops --points 10M --method sphere-compute -o d.png\n"
      "  pointrast render md.mmpld --method sphere-compute --layout soa8 -o md.png --json\n"
      "  pointrast render particles-laser --points 10M --method sphere-strip --billboard camera -o l.png");
  cmd->add_option("FILE", a->input,
                  "Point cloud file (" + io::formatList(io::FormatUse::Cloud) + "), particle file (" +
                      io::formatList(io::FormatUse::Particles) + ") or a scene name (terrain, tls)");
  cmd->add_option("-o,--output", a->output, "PNG to write (required unless --path)");
  cmd->add_option("--width", a->width, "Image width in pixels")->capture_default_str();
  cmd->add_option("--height", a->height, "Image height in pixels")->capture_default_str();
  cmd->add_option("--eye", a->eye, "Camera position x,y,z (default: overview)");
  cmd->add_option("--target", a->target, "Point looked at x,y,z (default: center of the bounds)");
  cmd->add_option("--up", a->up, "Up direction x,y,z")->capture_default_str();
  cmd->add_option("--fov", a->fov, "Vertical field of view in degrees")->capture_default_str();
  cmd->add_option("--near", a->nearW, "Drop points at linear depth <= near (0: 1e-5 x bounds diagonal)");
  cmd->add_option("--background", a->background, "Background color r,g,b (0..255)")->capture_default_str();
  cmd->add_option("--order", a->order, "Vertex order: original, morton, shuffled, shuffled-morton")
      ->capture_default_str();
  cmd->add_option(
         "--method", a->method,
         "Rasterization method, e.g. atomicmin (compute) or hw-points (the hardware GL_POINTS baseline); "
         "an unknown name lists them all")
      ->capture_default_str();
  cmd->add_option(
         "--depth", a->depth,
         "Depth encoding of the atomic methods: float (32-bit linear depth) or int40 (40-bit integer "
         "computed in double precision)")
      ->capture_default_str();
  cmd->add_option("--precision", a->precision,
                  "Batch methods: coordinate words per point, adaptive (the fewest that keep each batch's "
                  "error under half a pixel) or 1, 2, 3 (3 = full 30-bit precision)")
      ->capture_default_str();
  auto lodOption = [a](const std::string&) { a->lodOptionsGiven = true; };
  cmd->add_option(
         "--min-node-px", a->minNodePx,
         "LOD methods: skip octree nodes whose projected size (the pixel radius of the node's bounding "
         "sphere) is smaller, with their subtrees; 0 draws every point")
      ->capture_default_str()
      ->each(lodOption);
  cmd->add_option("--point-budget", a->pointBudget,
                  "LOD methods: most points drawn, largest nodes first (e.g. 100M; 0: no limit)")
      ->capture_default_str()
      ->each(lodOption);
  cmd->add_option(
         "--gpu-memory", a->gpuMemory,
         "LOD methods: GPU memory for the node cache (e.g. 8G; default: half the device's); a larger "
         "selection is drawn in several passes")
      ->each(lodOption);
  cmd->add_option("--seed", a->seed, "Seed for generated scenes and shuffled orders")->capture_default_str();
  cmd->add_option("--points", a->points, "Points of a generated scene (e.g. 1M, 1.2G)")
      ->capture_default_str();
  cmd->add_option("--frames", a->frames, "Timed frames; the median GPU time is reported")
      ->capture_default_str();
  cmd->add_option("--parts", a->parts, "Upload the cloud as N separate scenes drawn into one framebuffer")
      ->capture_default_str();
  cmd->add_option("--radius", a->radius,
                  "Sphere methods: radius of points drawn as spheres, or replacing an MMPLD file's radii");
  cmd->add_option("--frame", a->frame, "Sphere methods: the MMPLD frame to draw")->capture_default_str();
  cmd->add_option("--layout", a->layout,
                  "Sphere methods: GPU particle layout soa8, vec4x2, aos, xyz, or auto")
      ->capture_default_str();
  cmd->add_option("--billboard", a->billboard,
                  "Sphere pipelines that rasterize billboards: screen (the tight screen-space box of the "
                  "projected sphere, the default) or camera (a camera-aligned square, side 2r enlarged to "
                  "cover the sphere under perspective)");
  cmd->add_flag("--conservative", a->conservative,
                "Sphere pipelines that rasterize billboards: overestimating conservative rasterization "
                "(VK_EXT_conservative_rasterization; refused where the device lacks it)");
  cmd->add_option("--meshlet", a->meshlet,
                  "sphere-mesh-points, sphere-mesh-tris: spheres per mesh workgroup, 31 (default) or 15");
  cmd->add_flag("--task-cull", a->taskCull,
                "sphere-mesh-points, sphere-mesh-tris: a task shader culls spheres outside the view first "
                "and launches mesh workgroups only for the rest");
  cmd->add_option("--color", a->color,
                  "Point colors: auto (RGB if the file has it, else intensity, else elevation), rgb, "
                  "intensity, classification (ASPRS classes), elevation, return (return number), source "
                  "(point source id)")
      ->capture_default_str();
  cmd->add_option(
      "--color-range", a->colorRange,
      "lo,hi mapped to the ends of the intensity or elevation ramp (default: the 0.5 % and 99.5 % "
      "percentiles)");
  cmd->add_option("--point-size", a->pointSize,
                  "Point size in pixels (1..32); the closest point still wins every pixel")
      ->capture_default_str();
  cmd->add_option("--point-shape", a->pointShape, "Shape of points larger than a pixel: square or disc")
      ->capture_default_str();
  cmd->add_option(
         "--point-size-mode", a->pointSizeMode,
         "fixed (every point --point-size pixels) or attenuated (--point-size pixels at the target's "
         "distance, larger nearer and smaller farther, at most --point-size-max)")
      ->capture_default_str();
  cmd->add_option("--point-size-max", a->pointSizeMax, "Attenuated point sizes: the largest, pixels (1..32)")
      ->capture_default_str();
  cmd->add_option("--dilate", a->dilate,
                  "Fill holes up to R pixels wide with the closest point around them (0..8; 0: off); a far "
                  "point never covers a near one, and convex outlines do not grow")
      ->capture_default_str();
  cmd->add_flag("--edl", a->edl,
                "Eye-dome lighting (as Potree): shade each point by how far it lies behind "
                "its neighbours");
  cmd->add_option("--edl-strength", a->edlStrength, "Eye-dome lighting strength (default 1; implies --edl)");
  cmd->add_option("--edl-radius", a->edlRadius,
                  "Eye-dome lighting: distance of the 8 neighbours in pixels (default 1.4; implies --edl)");
  cmd->add_option("--device", a->device, "Vulkan device index (see `pointrast info --devices`)");
  cmd->add_flag("--json", a->json, "Print one JSON object with the result");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress or device lines");
  addPathOptions(*cmd, a->path);
  return [a] { return runRender(*a); };
}

} // namespace pointrast::app
