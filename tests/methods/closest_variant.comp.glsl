#version 460
// The test-only closest-point variant (method_rows.inc): the closest family's code with a row's own
// constants (early-z and ballot dedup), compiled as a shader of its own so that the row's shader name is
// one that no product row uses.
#define DEPTH_INT40 0
#define DEDUP_NV 0
#include "raster_closest.inc.glsl"
