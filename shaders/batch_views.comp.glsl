#version 460
// The box decisions of a part's batches (batch.inc.glsl's viewBox), one thread per batch and eye, into
// BatchFrame::views before the frame's drawing passes: a drawing workgroup then reads its batch's decision
// with one load (batch_part.inc.glsl, viewBatch) instead of waiting at two barriers while one of its threads
// runs the decision's long dependent chain.
#include "batch_part.inc.glsl"

void main() {
  FrameRef frame = FrameRef(pc.frame);
  uint batch = gl_GlobalInvocationID.x;
  if (batch * kBatchPoints >= pc.pointCount) return;
  BatchBounds bounds = BoundsArray(pc.bounds).v[batch];
  uint eyes = frame.f.eyes;
  bool clippedAll = true; // culled by the clip for every eye the frustum did not cull it for
  bool clippedAny = false;
  for (uint eye = 0u; eye < eyes; ++eye) {
    BatchCamera cam = batchCamera(frame, eye);
    BatchView v = viewBox(bounds.min.xyz, bounds.max.xyz, cam, frame.f.forcedWords, frame.f.culling != 0u);
    bool clipped;
    v = clipView(v, bounds.min.xyz, bounds.max.xyz, clipped);
    clippedAny = clippedAny || clipped;
    clippedAll = clippedAll && (clipped || v.words == 0u);
    v.rect = denseRect(v, cam, batch); // batch-hqs: which batches are dense, and which tiles they may touch
    BatchViews(frame.f.views).v[viewIndex(batch, eye, eyes)] = storeView(v);
  }
  if (COUNT != 0u && clippedAny && clippedAll) {
    uint row = (batch % kBatchStatSlots) * kBatchStatCount;
    atomicAdd(Uint64Array(frame.f.stats).v[row + kStatBatchesClipped], 1ul);
  }
}
