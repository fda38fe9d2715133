// Stereo rendering (the 2022 paper's VR section, 3.7): two eyes beside each other, each with its own camera
// derived from the one the user gives, drawn in one pass by the batch and LOD methods (every point read once,
// projected into both eyes' framebuffers side by side). The eye cameras follow what stereo tools expect:
// the eyes sit half the eye separation left and right of the given eye along the image's horizontal axis,
// look in parallel, and their frusta are shifted towards each other (off-axis, "asymmetric frustum") so
// that the plane at the convergence distance lies at the same pixels in both images (zero parallax: nearer
// points stand out of the screen, farther ones lie behind it). An infinite convergence distance gives
// parallel frusta, as a VR headset renders.
#pragma once

#include <cstdint>
#include <string_view>

#include "render/camera.h"

namespace pointrast {

enum class Eye { Left, Right };

struct StereoSettings {
  // Distance between the eyes in scene units; 0: the convergence distance / 30 (the "1/30 rule" of stereo
  // photography: comfortable depth whatever the scene's units). 0.064 is a human's, for a cloud in metres
  // seen life-size.
  double separation = 0.0;
  // Distance from the eye of the plane seen at zero parallax; 0: the target's distance; infinity: parallel
  // frusta (no shift).
  double convergence = 0.0;
  // The right eye's image on the left half (for cross-eyed free viewing); the left eye's otherwise.
  bool crossed = false;
};

// The separation and convergence distance `settings` give for a camera (defaults resolved).
double eyeSeparation(const Camera& camera, const StereoSettings& settings);
double convergenceDistance(const Camera& camera, const StereoSettings& settings);

// One eye's camera for an image of the given aspect (width / height of one eye).
Camera eyeCamera(const Camera& camera, const StereoSettings& settings, Eye eye, double aspect);

// The eye whose image lies in half `half` (0: left half) of the side-by-side image.
Eye eyeOfHalf(const StereoSettings& settings, uint32_t half);

// Throws InputError for a negative or non-finite separation or a convergence distance <= 0 (NaN included).
void validateStereo(const StereoSettings& settings);

// "inf", "infinity" or a positive number (render --convergence); throws InputError.
double parseConvergence(std::string_view text);

} // namespace pointrast
