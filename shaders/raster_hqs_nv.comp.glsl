#version 460
// HQS accumulation with VK_NV_shader_subgroup_partitioned aggregation (see raster_hqs.inc.glsl).
#define PARTITIONED_NV 1
#include "raster_hqs.inc.glsl"
