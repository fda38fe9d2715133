#version 460
// batch and batch-prefetch (see batch.inc.glsl and batch_draw.inc.glsl): one workgroup per batch of a part;
// the visibility index of a point is part << 26 | its index in the part. Colors are fetched by the resolve,
// for visible points only.
#include "batch_part.inc.glsl"

layout(constant_id = 0) const uint PREFETCH = 0;
layout(constant_id = 1) const uint DEPTH_ONLY = 0;
// 1: each thread's first words are loaded before the batch's decision (batch_draw.inc.glsl); 0 only to time
// the difference (method rows batch-prefetch-late, batch-prefetch-shared).
layout(constant_id = 3) const uint EARLY_HIGH = 1;

#include "batch_draw.inc.glsl"

void main() {
  beginStats();
  FrameRef frame = FrameRef(pc.frame);
  BatchCamera cam = batchCamera(frame, 0u);
  uint first = gl_WorkGroupID.x * kBatchPoints;
  uint count = min(kBatchPoints, pc.pointCount - first);
  if (EARLY_HIGH != 0u) loadFirstStepHigh(batchWords(first), count);
  BatchView v = viewBatch(gl_WorkGroupID.x, cam, frame.f.forcedWords, frame.f.culling != 0u);
  uint payloadBase = (pc.part << kVisibilityPartShift) | first;
  uint rendered = 0u, words = v.words;
  if (STEREO != 0u) {
    BatchCamera right = batchCamera(frame, 1u);
    BatchView v1 = viewBatch(gl_WorkGroupID.x, right, frame.f.forcedWords, frame.f.culling != 0u);
    rendered = drawBoxAsStereo(v, v1, batchWords(first), payloadBase, count, kBatchPoints,
                               kBatchPointsPerThread / GROUP, cam, right, frame.f.framebuffer);
    words = max(v.words, v1.words); // the words loaded
  } else {
    rendered = drawBoxAs(v, batchWords(first), payloadBase, count, kBatchPoints, kBatchPointsPerThread / GROUP,
                         cam, frame.f.framebuffer);
  }
  endStats(frame.f.stats, kStatPointsRendered, rendered, true, words, count);
}
