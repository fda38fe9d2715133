#version 460
// batch-hqs, first pass of the dense batches (batch_dense.inc.glsl): depth and blending together. It runs
// beside the depth pass of the other batches (raster_batch.comp with DEPTH_ONLY, which skips dense ones).
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_KHR_shader_subgroup_shuffle_relative : require
#extension GL_EXT_control_flow_attributes : require
#include "batch_part.inc.glsl"
#include "batch_dense.inc.glsl"

void main() {
  beginStats();
  FrameRef frame = FrameRef(pc.frame);
  uint first = gl_WorkGroupID.x * kBatchPoints;
  uint count = min(kBatchPoints, pc.pointCount - first);
  BatchView v = viewBatch(gl_WorkGroupID.x, 0u);
  bool dense = denseBatch(v);
  uint writes = 0u;
  if (dense) {
    BatchCamera cam = batchCamera(frame, 0u);
    DenseTargets t = DenseTargets(Uint64Array(frame.f.framebuffer), Uint64Array(frame.f.accumulators),
                                  UintArray(frame.f.denseDepths), cam.pitch * cam.height);
    writes = drawDense(v, batchWords(first), cam, t);
  }
  // A dense batch blends all its points here (hqs_dense_check.comp takes back those of flagged pixels); the
  // depth pass counts the other batches.
  endStatsOf2(frame.f.stats, kStatPointsBlended, dense ? kBatchPointsPerThread : 0u, kStatPointsRendered, writes,
              dense, v.words, count);
  if (COUNT != 0u && dense && gl_LocalInvocationIndex == 0u)
    atomicAdd(Uint64Array(frame.f.stats).v[(gl_WorkGroupID.x % kBatchStatSlots) * kBatchStatCount + kStatBatchesDense],
              1ul);
}
