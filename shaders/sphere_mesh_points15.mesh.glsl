#version 460
// sphere-mesh-points, 15 spheres per meshlet, consecutive spheres of a part (sphere_mesh.inc.glsl).
#define MESHLET 15
#define MESH_TRIS 0
#define MESH_TASK 0
#include "sphere_mesh.inc.glsl"
