#version 460
// Closest-point methods with float depth (see raster_closest.inc.glsl).
#define DEPTH_INT40 0
#define DEDUP_NV 0
#include "raster_closest.inc.glsl"
