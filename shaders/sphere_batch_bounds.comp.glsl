#version 460
// sphere-compute's occlusion culling, once per particle set: the bounds of every batch (kSphereBatchSize
// consecutive particles of a part), one thread per batch, its flag set and its entry written in the list
// at pc.particles (whose count the host sets), so that the first frame draws every batch before the test.
// Only spheres with a finite center and a positive finite radius (finiteSphere) count: a batch with none
// gets lo > hi and is never drawn (every sphere of it would be culled).
#include "sphere_raster.inc.glsl"
#include "grid.inc.glsl"

layout(local_size_x = kSphereGroupSize) in;
layout(push_constant) uniform Push { SpherePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer SphereBatchBounds {
  vec4 v[];
};

void main() {
  uint batch = linearInvocation(pc.groupsX, kSphereGroupSize);
  frame = SphereFrameRef(pc.frame).f;
  if (batch >= frame.batches) return;
  uint part = batch / frame.batchesPerPart;
  uint first = (batch - part * frame.batchesPerPart) * kSphereBatchSize;
  SpherePartRef ref = PartTable(frame.parts).v[part];
  vec3 lo = vec3(3.0e38), hi = vec3(-3.0e38);
  uint end = min(first + kSphereBatchSize, ref.count);
  for (uint i = first; i < end; ++i) {
    Sphere s = loadSphere(ref.address, ref.count, i);
    if (!finiteSphere(s.center, s.radius)) continue;
    lo = min(lo, s.center - s.radius);
    hi = max(hi, s.center + s.radius);
  }
  SphereBatchBounds(frame.batchBounds).v[2 * batch] = vec4(lo, 0.0);
  SphereBatchBounds(frame.batchBounds).v[2 * batch + 1] = vec4(hi, 0.0);
  UintArray(frame.batchFlags).v[batch] = 1u;
  SphereBatchList(pc.particles).entries[batch] = batch;
}
