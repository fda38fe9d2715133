#version 460
// The per-pixel lock of the 2013 GPGPU point pipeline (Guenther et al.), as evaluated in the 2021 paper:
// the framebuffer is a depth array and a color array; a point takes the pixel's lock by setting the lock
// bit in the depth word (test-and-set), writes its color, and releases by storing its depth. Early-z: a
// point farther than the stored depth gives up without locking (depth only ever decreases).
//
// Two hazards shape the loop:
// - Deadlock on hardware that runs a subgroup in lockstep (lavapipe, pre-Volta GPUs): a lane that wins the
//   lock finishes its critical section and releases in the same iteration, so no lane ever waits on a
//   lock held by a lane of its own subgroup that cannot advance.
// - lavapipe (Mesa 22.3) was seen to perform atomics for lanes masked off by divergent control flow,
//   with their stale operands: a lock bit set by a lane that had left the loop was never released. So the
//   loop runs while any lane of the subgroup is busy, every lane executes every atomic, and a lane with
//   nothing to do passes an identity operand (OR 0, XOR 0). The release is an XOR from the locked word to
//   the new depth, exact because nobody else changes a locked word.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#include "common.inc.glsl"

layout(local_size_x = kPointGroupSize) in;
layout(push_constant) uniform Push { RasterPush pc; };
#define DEPTH_INT40 0
#include "point.inc.glsl"

layout(buffer_reference, std430, buffer_reference_align = 4) coherent buffer CoherentUintArray { uint v[]; };

void main() {
  uint i = linearInvocation(pc.groupsX, kPointGroupSize);
  uint pixel = 0; // lanes without a point touch pixel 0 with identity operands only
  uint64_t word = 0;
  bool done = i >= pc.pointCount || !pointWord(i, pixel, word);
  if (done) pixel = 0;
  uint depthBits = uint(word >> 32);
  uint color = uint(word);
  CoherentUintArray depth = CoherentUintArray(pc.framebuffer);
  CoherentUintArray colors = CoherentUintArray(pc.framebuffer + uint64_t(pc.width) * pc.height * 4);

  while (subgroupAny(!done)) {
    uint current = atomicOr(depth.v[pixel], 0u); // an atomic read
    if (depthBits > (current & ~kPixelLockBit)) done = true; // early-z: farther than what is (being) stored
    bool tryLock = !done && (current & kPixelLockBit) == 0u;
    uint before = atomicOr(depth.v[pixel], tryLock ? kPixelLockBit : 0u);
    bool owner = tryLock && (before & kPixelLockBit) == 0u;
    uint oldDepth = before & ~kPixelLockBit; // can only be <= what `current` showed
    // Ties in depth go to the smaller color, as with the 64-bit atomicMin methods.
    bool closer = owner && (depthBits < oldDepth || (depthBits == oldDepth && color < colors.v[pixel]));
    if (closer) colors.v[pixel] = color;
    memoryBarrierBuffer();
    uint released = closer ? depthBits : oldDepth;
    atomicXor(depth.v[pixel], owner ? (oldDepth | kPixelLockBit) ^ released : 0u); // release
    if (owner) done = true;
  }
}
