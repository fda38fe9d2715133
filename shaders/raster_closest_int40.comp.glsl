#version 460
// Closest-point methods with the 40-bit integer depth of the 2019 poster, projected in double precision.
#define DEPTH_INT40 1
#define DEDUP_NV 0
#include "raster_closest.inc.glsl"
