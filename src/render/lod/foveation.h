// Foveated LOD (the 2022 paper, sections 3.7 and 4.3): how much larger a node must look to be drawn, the
// farther it lies from where the eye looks (selection.h applies it).
#pragma once

namespace pointrast::lod {

// Foveated LOD: distances from the gaze point (the centre of the image, or of each eye's image) are measured
// in half-diagonals of the image (0 at the centre, 1 at the corners), from the gaze point to the nearest
// pixel of the node's projected sphere.
struct Foveation {
  bool enabled = false;
  double radius = 0.3; // the fovea: within this distance nodes need minNodePx, as without foveation
  double periphery =
      3.0; // the factor minNodePx is multiplied by at distance 1 (linear from the fovea's edge)
};

// The factor of the projected size a node needs at distance `distance` from the gaze point (>= 1).
double foveationFactor(const Foveation& foveation, double distance);

} // namespace pointrast::lod
