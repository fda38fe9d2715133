// The benchmark's viewpoints, derived from a cloud's bounds alone so that every run of every method on
// every order of a data set sees exactly the same camera:
//   overview  the whole cloud in frame (render's default camera, overviewCamera())
//   closeup   the eye at the center of the bounds looking horizontally along +x, like the paper's
//             "inside" views: a near, dense foreground and most points outside the frustum (behind
//             or beside the eye)
//   outside   the eye beyond the -x face of the bounds looking along -x, away from the cloud: every
//             point is behind the eye, so the frame measures the cost of reading and culling alone
//
// The sphere suite (spheres2023) looks from orbits instead, after the study's close and far views: `count`
// cameras evenly spaced on a horizontal orbit around the center of the bounds, each looking at the center,
// z up, the first one from the south-west as the overview:
//   short     inside the bounds: an ellipse at half the bounds' extent along x and y, a quarter of the
//             half height above the center; the eye sits among the particles, many of them behind it
//   long      outside the bounds: 20 degrees above the horizon, as far as keeps the bounds' enclosing
//             sphere (so every particle) in the image
#pragma once

#include <span>
#include <string_view>
#include <vector>

#include "cloud/cloud.h"
#include "render/camera.h"

namespace pointrast::bench {

enum class View { Overview, Closeup, Outside };

// Parses "overview", "closeup", "outside"; throws InputError naming the choices.
View parseView(std::string_view name);
const char* viewName(View view);
std::span<const View> allViews();

// The camera of `view` for a cloud with these bounds and an image of this aspect (width / height).
Camera viewCamera(View view, const Bounds& bounds, double aspect, double fovY = 60.0);

enum class Orbit { Short, Long };

// Parses "short", "long"; throws InputError naming the choices.
Orbit parseOrbit(std::string_view name);
const char* orbitName(Orbit orbit);
std::span<const Orbit> allOrbits();

// The `count` cameras of an orbit around non-empty bounds, for an image of this aspect (width / height).
// Bounds without extent along x or y (a flat or single-particle set) cannot hold an eye: the short orbit
// then circles at a thousandth of the diagonal (at least 1e-3) outside them.
std::vector<Camera> orbitCameras(Orbit orbit, const Bounds& bounds, double aspect, double fovY = 60.0,
                                 uint32_t count = 10);

} // namespace pointrast::bench
