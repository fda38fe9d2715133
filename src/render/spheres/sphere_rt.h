// sphere-rt (VK_KHR_ray_tracing_pipeline; sphere_rt.cpp, shaders/sphere_rt*.glsl): the acceleration
// structure input pass, apart so that it runs and is tested on devices without ray tracing.
#pragma once

#include <cstdint>

#include "gpu/program.h"
#include "render/spheres/gpu_particles.h"

namespace pointrast {

// Bytes of one AABB of the bottom-level structure: VkAabbPositionsKHR, min xyz then max xyz as floats.
constexpr uint64_t kSphereAabbBytes = 24;

// Records the AABB pass of one part (program: "sphere_rt_aabbs.comp" with LAYOUT = the particles' layout):
// part.count boxes at `aabbs` (8-byte aligned, kSphereAabbBytes each), in the particles' frame, padded
// for the traversal's rounding, inactive (min.x = NaN) for particles every sphere method culls for their
// values. `frame`: a SphereFrame holding the set's global radius and color. The caller synchronizes the
// writes (compute shader, shader storage write) with their readers.
void recordSphereAabbs(VkCommandBuffer cmd, const gpu::ComputeProgram& program, uint64_t frame,
                       const ParticlePart& part, uint64_t aabbs);

} // namespace pointrast
