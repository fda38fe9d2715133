// What the culling task shader (sphere_mesh.task.glsl) hands to the mesh workgroups it launches: the
// surviving spheres of its 128, as offsets from `first` (the part-local index of its first sphere), in
// index order. 4 + 4 + 128 x 4 = 520 bytes, far below the 16 KiB of task payload every device has.
struct SphereMeshPayload {
  uint first;
  uint count;
  uint offsets[kSphereTaskSpheres];
};
taskPayloadSharedEXT SphereMeshPayload payload;
