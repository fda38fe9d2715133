// The procedural particle scenes behind generateParticles(), not part of the library's interface (tests
// use it to check that every particle is a pure function of its index).
//
// A scene lays itself out once from (count, seed): sizes, lattice dimensions, the objects of a scene and
// how many particles each gets. Particle i is then a pure function of (layout, i): its component comes
// from i (components are consecutive index ranges), its randomness from a splitmix64 stream seeded by
// (seed, i). So any index range can be written independently, by any thread.
#pragma once

#include <cstdint>
#include <memory>

#include "cloud/particles_generate.h"

namespace pointrast::detail {

class ParticleGenerator {
public:
  virtual ~ParticleGenerator() = default;
  // Writes particles [first, first + count): xyz[3k..3k+2] (relative to origin 0), colors[k], and
  // radius[k] when radius is not null (per-particle radii; otherwise every particle has the global one).
  virtual void generate(uint64_t first, uint64_t count, float* xyz, uint32_t* colors,
                        float* radius) const = 0;
};

// radius: the global radius, which per-particle radii vary around.
std::unique_ptr<ParticleGenerator> makeParticleGenerator(ParticleScene scene, uint64_t particles,
                                                         uint64_t seed, float radius);

} // namespace pointrast::detail
