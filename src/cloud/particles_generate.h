// Synthetic particle scenes (spheres), shaped after the data sets of "Efficient Sphere Rendering
// Revisited" (2023): molecular-dynamics snapshots with dense phases beside sparse ones. Deterministic for
// a given (scene, count, seed, radius options) whatever the number of threads, generated on all hardware
// threads at 16 B per particle (20 B with per-particle radii).
//
// Lengths are in units of the dense phases' nearest-neighbor distance, so the default radius 0.5 makes
// neighboring spheres touch; a scene grows with its particle count, as a simulation with more atoms
// covers more space. Colors come from particleRamp() over a physical-looking attribute.
#pragma once

#include <cstdint>
#include <string_view>

#include "cloud/particles.h"

namespace pointrast {

enum class ParticleScene {
  Block,   // "particles-block": a dense jittered lattice block between two vapor regions (Riemann data)
  Drops,   // "particles-drops": liquid droplets joined by filaments, in a vapor (the Drop/Fluid data)
  Laser,   // "particles-laser": a crystal slab with a molten crater and ejected clusters (Laser ablation)
  Uniform, // "particles-uniform": uniform random in a cube at unit density, for scaling measurements
};

// The names joined for messages and help: "particles-block, particles-drops, ...".
inline constexpr const char* kParticleSceneNames =
    "particles-block, particles-drops, particles-laser, particles-uniform";

// Parses a scene name; throws InputError naming the choices. isParticleSceneName() does not throw.
ParticleScene parseParticleScene(std::string_view name);
bool isParticleSceneName(std::string_view name);
const char* particleSceneName(ParticleScene scene);

struct ParticleGenerateOptions {
  uint64_t particles = 1'000'000;
  uint64_t seed = 1;
  // The global radius; with perParticleRadius the typical radius, each particle's varying around it by
  // its kind (gas atoms smaller, lattice atoms within a few percent).
  float radius = 0.5f;
  bool perParticleRadius = false;
  bool progress = true;
};

// Throws InputError for a radius that is not a positive finite number, or a count that cannot be held
// (more than 2^40 particles, more than this machine's memory, or a failed allocation).
ParticleSet generateParticles(ParticleScene scene, const ParticleGenerateOptions& options);

} // namespace pointrast
