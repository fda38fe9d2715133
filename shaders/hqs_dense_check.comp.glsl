#version 460
// batch-hqs, between the first pass and the accumulation pass: a pixel where a dense batch blended a point
// beyond 1 % of the closest depth (BatchFrame::denseDepths holds the farthest) has wrong sums. They hold only
// the dense batches' points at this stage, so they are set to zero, the pixel flagged (kHqsDenseFlagged)
// and its tile marked: the accumulation pass then blends the dense points of flagged pixels with the test of
// every other point. One thread per framebuffer pixel, 2D grid of 1D workgroups.
#include "batch_part.inc.glsl"

void main() {
  FrameRef frame = FrameRef(pc.frame);
  uint pitch = frame.f.pitch, pixels = pitch * frame.f.height;
  uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * kPointGroupSize + gl_LocalInvocationIndex;
  if (i == 0u) ++UintArray(frame.f.denseHistory).v[0]; // this frame's number (denseRect)
  if (i >= pixels) return;
  UintArray far = UintArray(frame.f.denseDepths);
  uint farthest = far.v[i];
  if (farthest == 0u) return; // no dense point
  float closest = uintBitsToFloat(uint(Uint64Array(frame.f.framebuffer).v[i] >> 32));
  if (!(uintBitsToFloat(farthest) > closest * float(PR_HQS_DEPTH_FACTOR))) return; // the blend pass's test
  Uint64Array acc = Uint64Array(frame.f.accumulators);
  if (COUNT != 0u) {
    uint64_t blended = (acc.v[i] >> 48) + (acc.v[pixels + 2u * i + 1u] & 0xFFFFFFFFul);
    uint row = ((i / kPointGroupSize) % kBatchStatSlots) * kBatchStatCount;
    atomicAdd(Uint64Array(frame.f.stats).v[row + kStatPointsBlended], -blended); // modular: a subtraction
    atomicAdd(Uint64Array(frame.f.stats).v[row + kStatPointsTakenBack], blended);
  }
  acc.v[i] = 0ul;
  acc.v[pixels + 2u * i] = 0ul;
  acc.v[pixels + 2u * i + 1u] = 0ul;
  far.v[i] = kHqsDenseFlagged;
  UintArray(frame.f.denseTiles).v[(i / pitch / kHqsDenseTile) * frame.f.tilesX + i % pitch / kHqsDenseTile] = 1u;
}
