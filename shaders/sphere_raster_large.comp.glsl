#version 460
// sphere-compute, pass 2: the chunks of large spheres listed by pass 1, one chunk of 256 box pixels per
// workgroup iteration, one pixel per thread. A fixed grid of workgroups strides over the list (the count
// is known only on the GPU; pc.groupsX is the number of workgroups), so no indirect dispatch is needed.
// The box travels in the entry, so this pass draws exactly the pixels pass 1 assigned.
#include "sphere_raster.inc.glsl"

layout(local_size_x = kSphereChunkPixels) in;
layout(push_constant) uniform Push { SpherePush pc; };

void main() {
  frame = SphereFrameRef(pc.frame).f;
  SphereChunks list = SphereChunks(frame.chunks);
  uint total = uint(min(list.count, uint64_t(frame.chunkCapacity)));
  for (uint e = gl_WorkGroupID.x; e < total; e += pc.groupsX) {
    uvec4 entry = list.entries[e];
    uint width = entry.z & 0xFFFFu, pixel = entry.w + gl_LocalInvocationIndex;
    if (pixel >= width * (entry.z >> 16)) continue;
    ivec2 p = ivec2(entry.y & 0xFFFFu, entry.y >> 16) + ivec2(pixel % width, pixel / width);
    Sphere s = sphereByIndex(entry.x);
    vec3 center;
    // Always true for a listed sphere (the same call as in pass 1).
    if (viewSphere(s, center)) coverPixel(center, s.radius, entry.x, p);
  }
}
