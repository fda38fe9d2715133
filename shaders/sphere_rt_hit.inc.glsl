// sphere-rt, for the stages that see a primitive (intersection, closest hit); after sphere_rt.inc.glsl.
// The index in its part of the particle of the current primitive: pieces of a part hold consecutive
// particles, pieceParticles each (shared.h, kSphereRtPieceBits).
uint sphereRtLocalIndex() {
  uint piece = uint(gl_InstanceCustomIndexEXT) & ((1u << kSphereRtPieceBits) - 1u);
  return piece * pc.pieceParticles + uint(gl_PrimitiveID);
}
