#version 460
// HQS accumulation, portable subgroup aggregation (see raster_hqs.inc.glsl).
#define PARTITIONED_NV 0
#include "raster_hqs.inc.glsl"
