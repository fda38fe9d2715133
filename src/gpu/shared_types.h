// C++ view of shaders/shared.h with layout checks: if a member moves, this fails to compile instead of
// the GPU reading garbage.
#pragma once

#include <cstddef>

#include "shared.h"

namespace pointrast::shared {

static_assert(sizeof(RasterPush) == 128); // the push-constant size every device must support
static_assert(offsetof(RasterPush, positions) == 64);
static_assert(offsetof(RasterPush, framebuffer) == 80);
static_assert(offsetof(RasterPush, viewProjD) == 96);
static_assert(offsetof(RasterPush, pointCount) == 104);
static_assert(offsetof(RasterPush, groupsX) == 120);
static_assert(sizeof(ResolvePush) == 48);
static_assert(offsetof(ResolvePush, width) == 32);
static_assert(sizeof(CopyPush) == 24);

} // namespace pointrast::shared
