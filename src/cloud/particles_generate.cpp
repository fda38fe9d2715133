#include "cloud/particles_generate.h"

#include <cmath>
#include <new>
#include <optional>
#include <string>
#include <unistd.h>

#include "base/error.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "cloud/particle_scenes.h"

namespace pointrast {

namespace {

constexpr const char* kNames[] = {"particles-block", "particles-drops", "particles-laser",
                                  "particles-uniform"};
// Fixed block size (64 Ki particles): the unit of work and of progress; results do not depend on it.
constexpr uint64_t kBlock = uint64_t(1) << 16;
constexpr uint64_t kMaxParticles = uint64_t(1) << 40;

} // namespace

ParticleScene parseParticleScene(std::string_view name) {
  for (int k = 0; k < 4; ++k)
    if (name == kNames[k]) return static_cast<ParticleScene>(k);
  throw InputError("unknown particle scene '" + std::string(name) + "' (choices: " + kParticleSceneNames +
                   ")");
}

bool isParticleSceneName(std::string_view name) {
  for (const char* n : kNames)
    if (name == n) return true;
  return false;
}

const char* particleSceneName(ParticleScene scene) {
  return kNames[static_cast<int>(scene)];
}

ParticleSet generateParticles(ParticleScene scene, const ParticleGenerateOptions& options) {
  const uint64_t n = options.particles;
  const std::string what = std::string(particleSceneName(scene)) + ", " + std::to_string(n) +
                           " particles, seed " + std::to_string(options.seed);
  if (!(options.radius > 0) || !std::isfinite(options.radius))
    throw InputError("cannot generate " + what + ": the radius must be a positive number, not " +
                     std::to_string(options.radius));
  if (n > kMaxParticles)
    throw InputError("cannot generate " + what + ": at most 2^40 (" + std::to_string(kMaxParticles) +
                     ") particles");
  // Refuse up front what cannot fit in physical memory, rather than being killed half way.
  const double bytesPerParticle =
      3 * sizeof(float) + sizeof(uint32_t) + (options.perParticleRadius ? sizeof(float) : 0);
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && pageSize > 0 && double(n) * bytesPerParticle > double(pages) * double(pageSize))
    throw InputError("cannot generate " + what + ": needs " + humanCount(double(n) * bytesPerParticle) +
                     "B, more than this machine's memory (" + humanCount(double(pages) * double(pageSize)) +
                     "B)");

  ParticleSet set;
  set.source = what;
  set.globalRadius = options.radius;
  try {
    // Allocated once; generation writes in place.
    set.xyz.resize(3 * n);
    set.colors.resize(n);
    if (options.perParticleRadius) set.radius.resize(n);
  } catch (const std::bad_alloc&) {
    throw InputError("cannot generate " + what + ": out of memory");
  }
  auto generator = detail::makeParticleGenerator(scene, n, options.seed, options.radius);
  std::optional<Progress> progress;
  if (options.progress)
    progress.emplace("generating " + std::string(particleSceneName(scene)), n, " particles");
  parallelBlocks(n, kBlock, [&](uint64_t, uint64_t begin, uint64_t end) {
    generator->generate(begin, end - begin, set.xyz.data() + 3 * begin, set.colors.data() + begin,
                        options.perParticleRadius ? set.radius.data() + begin : nullptr);
    if (progress) progress->advance(end - begin);
  });
  if (progress) progress->finish();
  computeBounds(set);
  return set;
}

} // namespace pointrast
