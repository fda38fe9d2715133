// The benchmark's viewpoints, derived from a cloud's bounds alone so that every run of every method on
// every order of a data set sees exactly the same camera:
//   overview  the whole cloud in frame (render's default camera, overviewCamera())
//   closeup   the eye at the center of the bounds looking horizontally along +x, like the paper's
//             "inside" views: a near, dense foreground and most points outside the frustum (behind
//             or beside the eye)
//   outside   the eye beyond the -x face of the bounds looking along -x, away from the cloud: every
//             point is behind the eye, so the frame measures the cost of reading and culling alone
#pragma once

#include <span>
#include <string_view>

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

} // namespace pointrast::bench
