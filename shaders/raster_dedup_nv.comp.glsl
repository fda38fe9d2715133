#version 460
// dedup with VK_NV_shader_subgroup_partitioned, float depth.
#define DEPTH_INT40 0
#define DEDUP_NV 1
#include "raster_closest.inc.glsl"
