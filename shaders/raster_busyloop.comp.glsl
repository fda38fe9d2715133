#version 460
// The per-pixel lock of the 2013 GPGPU point pipeline (Guenther et al.), as evaluated in the 2021 paper:
// the framebuffer is a depth array and a color array; a point takes the pixel's lock by compare-and-swap
// of the lock bit in the depth word, writes its color, and releases by storing its depth. Early-z: a
// point farther than the stored depth gives up without locking (depth only ever decreases).
//
// Why it cannot deadlock on hardware that runs a subgroup in lockstep (pre-Volta GPUs): a lane that wins
// the lock finishes its critical section and releases in the same loop iteration, so no lane ever waits
// on a lock held by a lane of its own subgroup that cannot advance.
//
// RELEASE orders the color store before the release on GPUs: 1 = the lock taken with acquire and
// released with release semantics (memory scope semantics), 0 = nothing. On lavapipe (Mesa 22.3) a buffer
// memory barrier appeared to park the invocation until the other subgroups of its workgroup reached one; a
// lane spinning on its lock never does, lavapipe's loop limiter ended the spin and the point was lost
// (pixels were left locked). CPU devices need no ordering there: x86 keeps the store before the
// sequentially consistent atomic that releases. So it is 0 on CPU devices.
#extension GL_KHR_memory_scope_semantics : require
#include "common.inc.glsl"
#include "grid.inc.glsl"

layout(local_size_x = kPointGroupSize) in;
layout(push_constant) uniform Push { RasterPush pc; };
layout(constant_id = 0) const uint RELEASE = 1;
#define DEPTH_INT40 0
#include "point.inc.glsl"

layout(buffer_reference, std430, buffer_reference_align = 4) coherent buffer CoherentUintArray { uint v[]; };

void main() {
  uint i = linearInvocation(pc.groupsX, kPointGroupSize);
  if (i >= pc.pointCount) return;
  uint pixel;
  uint64_t word;
  if (!pointWord(i, true, pixel, word)) return;
  uint depthBits = uint(word >> 32);
  uint color = uint(word);
  CoherentUintArray depth = CoherentUintArray(pc.framebuffer);
  CoherentUintArray colors = CoherentUintArray(pc.framebuffer + uint64_t(pc.width) * pc.height * 4);

  bool done = false;
  while (!done) {
    uint old = atomicOr(depth.v[pixel], 0u); // an atomic read of the current word
    uint oldDepth = old & ~kPixelLockBit;
    if (depthBits > oldDepth) {
      done = true; // early-z: farther than what is (or is being) stored
    } else if ((old & kPixelLockBit) == 0u) {
      uint seen = RELEASE == 1 ? atomicCompSwap(depth.v[pixel], old, old | kPixelLockBit, gl_ScopeDevice,
                                                gl_StorageSemanticsBuffer, gl_SemanticsAcquire,
                                                gl_StorageSemanticsBuffer, gl_SemanticsRelaxed)
                               : atomicCompSwap(depth.v[pixel], old, old | kPixelLockBit);
      if (seen == old) {
        // Locked. Ties in depth go to the smaller color, as with the 64-bit atomicMin methods.
        bool closer = depthBits < oldDepth || color < colors.v[pixel];
        if (closer) colors.v[pixel] = color;
        uint released = closer ? depthBits : oldDepth;
        if (RELEASE == 1)
          atomicExchange(depth.v[pixel], released, gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsRelease);
        else
          atomicExchange(depth.v[pixel], released);
        done = true;
      }
    }
  }
}
