// Host-side definitions shared by the GPU sphere renderers and the CPU ray caster (no Vulkan here).
#pragma once

#include <cstdint>

#include "cloud/particles.h"
#include "gpu/shared_types.h"

namespace pointrast {

// Particle index of a pixel that no sphere covers (shared.h).
constexpr uint32_t kNoParticle = shared::kNoParticle;

// Bounds of the spheres (centers +- radius) in world coordinates; particles with a non-finite center or
// a radius that is not a positive finite number (which no renderer draws) are left out.
Bounds sphereSetBounds(const ParticleSet& set);

} // namespace pointrast
