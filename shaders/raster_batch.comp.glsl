#version 460
// batch and batch-prefetch (see batch.inc.glsl and batch_draw.inc.glsl): one workgroup per batch of a part;
// the visibility index of a point is part << 26 | its index in the part. Colors are fetched by the resolve,
// for visible points only.
#include "batch_part.inc.glsl"

layout(constant_id = 0) const uint PREFETCH = 0;
layout(constant_id = 1) const uint DEPTH_ONLY = 0;

#include "batch_draw.inc.glsl"

void main() {
  beginStats();
  FrameRef frame = FrameRef(pc.frame);
  BatchCamera cam = batchCamera(frame.f);
  uint first = gl_WorkGroupID.x * kBatchPoints;
  uint count = min(kBatchPoints, pc.pointCount - first);
  BatchView v = viewBatch(gl_WorkGroupID.x, cam, frame.f.forcedWords, frame.f.culling != 0u);
  uint payloadBase = (pc.part << kVisibilityPartShift) | first;
  uint rendered = drawBoxAs(v, batchWords(first), payloadBase, count, kBatchPoints,
                            kBatchPointsPerThread / GROUP, cam, frame.f.framebuffer);
  endStats(frame.f.stats, kStatPointsRendered, rendered, true, v.words, count);
}
