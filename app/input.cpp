#include "input.h"

#include <cmath>
#include <filesystem>

#include "base/error.h"
#include "cloud/generate.h"
#include "cloud/particles_generate.h"
#include "io/format_table.h"
#include "io/particles_io.h"
#include "io/reader.h"

namespace pointrast::app {

PointCloud loadInput(const InputSpec& spec) {
  PointCloud cloud;
  std::string source = spec.source.empty() ? kDemoScene : spec.source;
  std::error_code ec;
  if (std::filesystem::exists(source, ec)) {
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
  std::error_code ec;
  if (std::filesystem::exists(source, ec)) {
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

} // namespace pointrast::app
