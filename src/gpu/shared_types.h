// C++ view of shaders/shared.h with layout checks: if a member moves, this fails to compile instead of
// the GPU reading garbage.
#pragma once

#include <cstddef>

#include "shared.h"

namespace pointrast::shared {

static_assert(sizeof(RasterPush) == 112);
static_assert(offsetof(RasterPush, positions) == 64);
static_assert(offsetof(RasterPush, framebuffer) == 80);
static_assert(offsetof(RasterPush, pointCount) == 88);
static_assert(offsetof(RasterPush, groupsX) == 104);
static_assert(sizeof(ResolvePush) == 32);
static_assert(offsetof(ResolvePush, width) == 16);

} // namespace pointrast::shared
