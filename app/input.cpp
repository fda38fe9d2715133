#include "input.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "base/error.h"
#include "bench/octree_cache.h"
#include "cli_util.h"
#include "cloud/generate.h"
#include "cloud/octree.h"
#include "cloud/particles_generate.h"
#include "distributed.h"
#include "io/format_table.h"
#include "io/particles/particles_io.h"
#include "io/reader.h"
#include "mpi/mpi_job.h"

namespace pointrast::app {

bool pathExists(const std::string& path) {
  std::error_code ec;
  const bool found = std::filesystem::exists(path, ec);
  if (ec) throw InputError(path + ": cannot open: " + ec.message());
  return found;
}

PointCloud loadInput(const InputSpec& spec) {
  PointCloud cloud;
  std::string source = spec.source.empty() ? kDemoScene : spec.source;
  if (pathExists(source)) {
    io::ReadOptions options;
    options.progress = spec.progress;
    cloud = io::readCloud(source, options);
  } else if (isSceneName(source)) {
    GenerateOptions options;
    options.points = spec.source.empty() ? kDemoPoints : spec.points;
    options.seed = spec.seed;
    options.progress = spec.progress;
    options.classification = spec.classification;
    cloud = generateScene(parseScene(source), options);
  } else {
    throw InputError(source + ": no such file, and not a scene name (terrain, tls)");
  }
  reorder(cloud, spec.order, spec.seed);
  return cloud;
}

namespace {

// What a LOD method, or a cloud too large for the budget, opens.
enum class Opens { Cloud, Octree, BuiltOctree };

// How the input opens. Throws InputError for a LOD method and an input that no octree can be had from (a
// generated scene), and for a method that draws uploaded clouds and an octree that is nothing else.
Opens howOpens(const InputSpec& spec, const SceneOptions& options) {
  const std::optional<Method>& method = options.method;
  const bool lodMethod = method && methodInfo(*method).layout == SceneLayout::Octree;
  const std::string source = spec.source.empty() ? kDemoScene : spec.source;
  const io::FormatInfo* format = pathExists(source) ? io::detectFormat(source) : nullptr;
  const bool octree = format && format->openNodes;
  if (octree) {
    if (method && !lodMethod && !format->read)
      throw InputError(source + " is an octree (" + format->name + "), drawn by the LOD methods (" +
                       methodNamesReading(SceneLayout::Octree) + "), not " + methodName(*method));
    return !method || lodMethod ? Opens::Octree : Opens::Cloud;
  }
  const bool cloudFile = format && format->read && format->content == io::FormatContent::Points;
  if (lodMethod && !cloudFile)
    throw InputError(std::string(methodName(*method)) + " draws octrees (" +
                     io::formatList(io::FormatUse::Octree) + "); " +
                     (spec.source.empty() ? std::string("the demo scene") : spec.source) +
                     " is a generated scene: build one with `pointrast lod FILE -o DIR`");
  if (!cloudFile || (method && !lodMethod)) return Opens::Cloud;
  if (lodMethod) return Opens::BuiltOctree;
  if (options.gpuBudget == 0) return Opens::Cloud;
  const std::optional<uint64_t> points = io::statedPointCount(source);
  constexpr uint64_t kUploadBytesPerPoint = 16; // float xyz + RGBA8 (SceneLayout::Float)
  return points && *points > options.gpuBudget / kUploadBytesPerPoint ? Opens::BuiltOctree : Opens::Cloud;
}

} // namespace

std::string fileOctreeKey(const std::filesystem::path& file) {
  std::error_code error;
  const std::filesystem::path absolute = std::filesystem::absolute(file, error);
  const uint64_t size = std::filesystem::file_size(file, error);
  const auto modified = std::filesystem::last_write_time(file, error).time_since_epoch().count();
  const std::string identity =
      absolute.string() + "\n" + std::to_string(size) + "\n" + std::to_string(int64_t(modified));
  uint64_t hash = 14695981039346656037ull; // FNV-1a, 64 bits
  for (unsigned char c : identity)
    hash = (hash ^ c) * 1099511628211ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  std::string stem = file.filename().string();
  for (char& c : stem)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  return "file-" + stem + "-" + hex;
}

void checkSceneMethod(const InputSpec& spec, std::optional<Method> method) {
  SceneOptions options;
  options.method = method;
  if (howOpens(spec, options) == Opens::Octree && spec.order != Order::Original)
    throw InputError("--order does not apply to " + spec.source + ", an octree drawn in its nodes' order");
}

view::SceneInput openScene(const InputSpec& spec, const SceneOptions& options) {
  checkSceneMethod(spec, options.method);
  switch (howOpens(spec, options)) {
  case Opens::Octree:
    return view::SceneInput::fromOctree(io::openNodeSource(spec.source));
  case Opens::BuiltOctree: {
    bench::OctreeCacheOptions cache;
    cache.dir = options.octreeCache.empty() ? bench::defaultOctreeCacheDir() : options.octreeCache;
    cache.progress = spec.progress;
    cache.onNote = options.onNote;
    std::optional<PointCloud> cloud;
    const bench::DatasetOctree octree = bench::octreeCache(cache)(fileOctreeKey(spec.source), [&]() -> const PointCloud& {
      cloud = loadInput(spec);
      return *cloud;
    });
    return view::SceneInput::fromOctree(io::openNodeSource(octree.path));
  }
  case Opens::Cloud:
    break;
  }
  return view::SceneInput::fromCloud(loadInput(spec));
}

view::SceneInput openSceneShare(const InputSpec& spec, const SceneOptions& options) {
  checkSceneMethod(spec, options.method);
  switch (howOpens(spec, options)) {
  case Opens::Octree:
    return view::SceneInput::fromOctree(io::openNodeSource(spec.source));
  case Opens::BuiltOctree:
    throw InputError(spec.source +
                     ": under mpirun serve draws a cloud's shares or an octree's, and builds "
                     "no octree; build one with `pointrast lod " +
                     spec.source + " -o DIR` and serve that");
  case Opens::Cloud:
    break;
  }
  // Each rank's points; the bounds, and the count the page shows, are the whole input's.
  view::SceneInput input = view::SceneInput::fromCloud(loadShare(spec));
  input.points = mpi::Job::get().sumOf(input.points);
  return input;
}

std::optional<uint64_t> statedPoints(const InputSpec& spec) {
  const std::string source = spec.source.empty() ? kDemoScene : spec.source;
  if (pathExists(source)) return io::statedPointCount(source);
  if (isSceneName(source)) return spec.source.empty() ? kDemoPoints : spec.points;
  return std::nullopt;
}

ParticleSet loadParticles(const ParticleInputSpec& spec) {
  if (!(spec.radius >= 0) || !std::isfinite(spec.radius))
    throw InputError("--radius expects a positive number, got " + std::to_string(spec.radius));
  const std::string source = spec.source.empty() ? kDemoParticleScene : spec.source;
  // Points have no size: drawing them as spheres takes a radius from the user.
  auto pointsAsSpheres = [&](PointCloud cloud) {
    if (spec.radius == 0)
      throw InputError(source + ": points drawn as spheres need a radius (--radius R, in the cloud's units)");
    return particlesFromCloud(cloud, spec.radius);
  };
  if (pathExists(source)) {
    const io::FormatInfo* format = io::detectFormat(source);
    if (!format || format->content != io::FormatContent::Particles) {
      io::ReadOptions options;
      options.progress = spec.progress;
      return pointsAsSpheres(io::readCloud(source, options));
    }
    io::MmpldReadOptions options;
    options.frame = spec.frame;
    options.progress = spec.progress;
    ParticleSet set = io::readMmpld(source, options);
    if (spec.radius > 0) {
      set.radius.clear();
      set.globalRadius = spec.radius;
    }
    return set;
  }
  if (isParticleSceneName(source)) {
    ParticleGenerateOptions options;
    options.particles = spec.source.empty() ? kDemoPoints : spec.particles;
    options.seed = spec.seed;
    if (spec.radius > 0) options.radius = spec.radius;
    options.perParticleRadius = spec.perParticleRadius;
    options.progress = spec.progress;
    return generateParticles(parseParticleScene(source), options);
  }
  if (isSceneName(source)) {
    GenerateOptions options;
    options.points = spec.particles;
    options.seed = spec.seed;
    options.progress = spec.progress;
    return pointsAsSpheres(generateScene(parseScene(source), options));
  }
  throw InputError(source + ": no such file, and not a scene name (particle scenes: " + kParticleSceneNames +
                   "; point scenes, with --radius: terrain, tls)");
}

std::optional<uint64_t> statedParticles(const ParticleInputSpec& spec) {
  const std::string source = spec.source.empty() ? kDemoParticleScene : spec.source;
  if (pathExists(source)) {
    const io::FormatInfo* format = io::detectFormat(source);
    if (format && format->content == io::FormatContent::Particles)
      return io::probeMmpld(source, spec.frame).particles();
    return io::statedPointCount(source);
  }
  if (isParticleSceneName(source)) return spec.source.empty() ? kDemoPoints : spec.particles;
  if (isSceneName(source)) return spec.particles;
  return std::nullopt;
}

InputSpec inputSpec(const std::string& source, const std::string& points, uint64_t seed,
                    const std::string& order, bool quiet) {
  InputSpec spec;
  spec.source = source;
  spec.points = parseCount(points, "--points");
  spec.seed = seed;
  spec.order = parseOrder(order);
  spec.progress = !quiet;
  return spec;
}

std::optional<Camera> cameraFromOptions(const std::string& eye, const std::string& target,
                                        const std::string& up, double fov, const glm::dvec3& center) {
  if (!target.empty() && eye.empty()) throw InputError("--target needs --eye");
  if (eye.empty()) return std::nullopt;
  Camera camera;
  camera.eye = parseVec3(eye, "--eye");
  camera.target = target.empty() ? center : parseVec3(target, "--target");
  camera.up = parseVec3(up, "--up");
  camera.fovY = fov;
  validateCamera(camera);
  return camera;
}

} // namespace pointrast::app
