#version 460
// sphere-mesh-tris, 15 spheres per meshlet, fed by the culling task shader (sphere_mesh.inc.glsl).
#define MESHLET 15
#define MESH_TRIS 1
#define MESH_TASK 1
#include "sphere_mesh.inc.glsl"
