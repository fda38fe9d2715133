#include "input.h"

#include <cmath>
#include <filesystem>

#include "base/error.h"
#include "cli_util.h"
#include "cloud/generate.h"
#include "cloud/particles_generate.h"
#include "io/format_table.h"
#include "io/particles/particles_io.h"
#include "io/reader.h"

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
    cloud = generateScene(parseScene(source), options);
  } else {
    throw InputError(source + ": no such file, and not a scene name (terrain, tls)");
  }
  reorder(cloud, spec.order, spec.seed);
  return cloud;
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
