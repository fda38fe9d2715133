// Host-side definitions shared by the GPU sphere renderers and the CPU ray caster (no Vulkan here).
#pragma once

#include <cstdint>

#include "cloud/particles.h"
#include "gpu/shared_types.h"

namespace pointrast {

// Particle index of a pixel that no sphere covers (shared.h).
constexpr uint32_t kNoParticle = shared::kNoParticle;

} // namespace pointrast
