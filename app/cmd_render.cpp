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
#include "bench/report.h"
#include "cli_util.h"
#include "cloud/particles_generate.h"
#include "commands.h"
#include "gpu/context.h"
#include "gpu/shared_types.h"
#include "input.h"
#include "io/format_table.h"
#include "io/writer.h"
#include "render/renderer.h"
#include "render/spheres/sphere_renderer.h"
#include "render_path.h"

namespace pointrast::app {

namespace {

struct RenderArgs {
  std::string input, output, eye, target, up = "0,0,1", background = "0,0,0", order = "original";
  std::string method = "atomicmin", points = "1M", depth = "float";
  std::string precision = "adaptive"; // batch methods
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
};

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
  if (settings.precision != 0 && layout != SceneLayout::Batched)
    throw InputError("--precision applies to the batch methods (" + methodNamesReading(SceneLayout::Batched) +
                     ")");
  settings.background = parseRgb(a.background, "--background");
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
  cmd->add_option("--device", a->device, "Vulkan device index (see `pointrast info --devices`)");
  cmd->add_flag("--json", a->json, "Print one JSON object with the result");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress or device lines");
  addPathOptions(*cmd, a->path);
  return [a] { return runRender(*a); };
}

} // namespace pointrast::app
