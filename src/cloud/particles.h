// The host model of a particle set (spheres): float32 positions relative to a double-precision origin,
// a radius per particle or one global radius, and an RGBA8 color per particle or one global color.
// This is what MMPLD carries (positions float or double, radius global or per particle, color global or
// per particle) and what the sphere renderers draw.
//
// Memory per particle: 12 B positions + 4 B radius (if per particle) + 4 B color (if per particle).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cloud/cloud.h"

namespace pointrast {

struct ParticleSet {
  glm::dvec3 origin{0.0};        // world = origin + double(xyz)
  std::vector<float> xyz;         // 3 per particle, relative to origin
  std::vector<float> radius;      // one per particle; empty: globalRadius for every particle
  float globalRadius = 1.0f;
  std::vector<uint32_t> colors;   // packRgba per particle; empty: globalColor for every particle
  uint32_t globalColor = packRgba(192, 192, 192);
  Bounds bounds;                  // of world positions, centers only (sphereBounds() adds the radii)
  std::string source;             // file name or scene description, for messages

  uint64_t size() const { return xyz.size() / 3; }
  bool perParticleRadius() const { return !radius.empty(); }
  bool perParticleColor() const { return !colors.empty(); }
  float radiusOf(uint64_t i) const { return radius.empty() ? globalRadius : radius[i]; }
  uint32_t colorOf(uint64_t i) const { return colors.empty() ? globalColor : colors[i]; }
  glm::dvec3 world(uint64_t i) const {
    return origin + glm::dvec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  }
};

// Recomputes set.bounds (centers) from the particles, on all hardware threads. Positions must be finite
// (every reader and generator guarantees it).
void computeBounds(ParticleSet& set);

// Bounds of the spheres: each center expanded by its radius, in double precision, from the particles
// themselves. Particles with a non-finite center or a radius that is not a positive finite number (which
// no renderer draws) are left out. Empty for an empty set.
Bounds sphereBounds(const ParticleSet& set);

// Smallest and largest radius over the particles: {globalRadius, globalRadius} without per-particle
// radii, {0, 0} for an empty set with per-particle radii.
struct RadiusRange {
  float min = 0, max = 0;
};
RadiusRange radiusRange(const ParticleSet& set);

// The color ramp for scalar particle attributes (MMPLD intensities, the generated scenes' phases and
// speeds): Turbo, as used for point clouds without color. t is clamped to [0, 1]; NaN gives the low end.
uint32_t particleRamp(double t);

// A point cloud drawn as spheres of one radius (radius > 0, in the cloud's units): positions relative to
// cloud.origin(), colors as displayColors() shows the points (RGB, else an intensity or elevation ramp).
// Memory: 16 B per point beside the cloud.
ParticleSet particlesFromCloud(const PointCloud& cloud, float radius);

} // namespace pointrast
