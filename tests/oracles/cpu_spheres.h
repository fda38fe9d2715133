// The CPU reference of the sphere renderers: an independent ray caster in double precision. For every
// pixel, the ray through its center (docs/design.md's camera contract, built from the camera's basis rather
// than from the GPU's matrices) is intersected with every sphere that may cover it, the nearest hit wins
// (lower index on equal depth, like the GPU's visibility word), and the hit is shaded with the formula of
// shaders/sphere_shade.inc.glsl. Culling follows the GPU's rule: a sphere is drawn only if it lies
// entirely beyond the near plane (center depth - radius > near) and has a finite center and a positive
// finite radius; spheres crossing the near plane are dropped whole, never clipped.
#pragma once

#include <cstdint>
#include <vector>

#include "cloud/particles.h"
#include "render/camera.h"
#include "render/spheres/spheres.h"

namespace pointrast {

struct SphereRaycast {
  uint32_t width = 0, height = 0;
  std::vector<uint32_t> image; // RGBA8, row 0 at the top; background where no sphere
  std::vector<double> depth;   // linear view depth of the hit; +infinity where no sphere
  std::vector<uint32_t> index; // particle index of the hit; kNoParticle where no sphere
  // 1 - (distance of the ray from the center / radius)^2 of the hit: 1 in the middle of the disc, 0 at
  // its silhouette, where the depth is ill-conditioned (it moves by sqrt of an error in the position).
  std::vector<float> centrality;
};

struct SphereRaycastOptions {
  uint32_t background = 0xFF000000u;
  // Ray-test every sphere at every pixel instead of only the pixels of a conservative screen box (the
  // projected corners of the sphere's bounding cube): the check that screen-space culling never loses a
  // visible sphere. Cost: pixels x spheres.
  bool bruteForce = false;
};

// near = camera.nearW, or defaultNear(sphereBounds(set)) when it is 0 (as the GPU renderer does).
SphereRaycast raycastSpheres(const ParticleSet& set, const Camera& camera, uint32_t width, uint32_t height,
                             const SphereRaycastOptions& options = {});

} // namespace pointrast
