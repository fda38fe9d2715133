#version 460
// batch and batch-prefetch (see batch.inc.glsl and batch_draw.inc.glsl): one workgroup per batch of a part;
// the visibility index of a point is part << 26 | its index in the part. Colors are fetched by the resolve,
// for visible points only.
#extension GL_KHR_shader_subgroup_basic : require
#include "batch_part.inc.glsl"

layout(constant_id = 0) const uint PREFETCH = 0;
layout(constant_id = 1) const uint DEPTH_ONLY = 0;

#include "batch_draw.inc.glsl"

void main() {
  beginStats();
  FrameRef frame = FrameRef(pc.frame);
  BatchCamera cam = batchCamera(frame, 0u);
  uint first = gl_WorkGroupID.x * kBatchPoints;
  uint count = min(kBatchPoints, pc.pointCount - first);
  BatchView v = viewBatch(gl_WorkGroupID.x, 0u);
  uint payloadBase = (pc.part << kVisibilityPartShift) | first;
  uint rendered = 0u, words = v.words;
  // batch-hqs's depth pass leaves the dense batches to raster_batch_hqs_dense.comp, which counts them.
  bool dense = DEPTH_ONLY != 0u && denseBatch(v);
  if (dense) {
  } else if (STEREO != 0u) {
    BatchCamera right = batchCamera(frame, 1u);
    BatchView v1 = viewBatch(gl_WorkGroupID.x, 1u);
    rendered = drawBoxAsStereo(v, v1, batchWords(first), payloadBase, count, kBatchPoints,
                               kBatchPointsPerThread / GROUP, cam, right, frame.f.framebuffer);
    words = max(v.words, v1.words); // the words loaded
  } else {
    rendered = drawBoxAs(v, batchWords(first), payloadBase, count, kBatchPoints, kBatchPointsPerThread / GROUP,
                         cam, frame.f.framebuffer);
  }
  endStats(frame.f.stats, kStatPointsRendered, rendered, !dense, words, count);
}
