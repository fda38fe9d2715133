#version 460
// batch-hqs, accumulation pass (2022): after a depth pass (raster_batch.comp with PREFETCH and DEPTH_ONLY),
// each batch of a part blends its points with batch_blend.inc.glsl. Dense batches blended in the first pass
// (raster_batch_hqs_dense.comp) blend here only their points on pixels hqs_dense_check.comp flagged.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_KHR_shader_subgroup_shuffle_relative : require
#extension GL_EXT_control_flow_attributes : require
#include "batch_part.inc.glsl"
#include "hqs_accumulate.inc.glsl"
#include "batch_blend.inc.glsl"
#include "batch_dense.inc.glsl"

void main() {
  beginStats();
  FrameRef frame = FrameRef(pc.frame);
  BatchCamera cam = batchCamera(frame, 0u);
  uint first = gl_WorkGroupID.x * kBatchPoints;
  uint count = min(kBatchPoints, pc.pointCount - first);
  BatchView v = viewBatch(gl_WorkGroupID.x, 0u);
  uint blended = 0u;
  if (STEREO != 0u) {
    BatchCamera right = batchCamera(frame, 1u);
    BatchView v1 = viewBatch(gl_WorkGroupID.x, 1u);
    blended = blendBoxStereo(v, v1, batchWords(first), count, kBatchPrefetchSteps, cam, right,
                             frame.f.framebuffer, frame.f.accumulators);
  } else if (!denseBatch(v)) {
    blended = blendBox(v, batchWords(first), count, kBatchPrefetchSteps, cam, frame.f.framebuffer,
                       frame.f.accumulators, 0ul);
  } else if (denseBatchFlagged(v, frame.f.denseTiles, frame.f.tilesX)) {
    // A dense batch blended in the first pass; here only its points on the pixels found wrong, if any.
    blended = blendBox(v, batchWords(first), count, kBatchPrefetchSteps, cam, frame.f.framebuffer,
                       frame.f.accumulators, frame.f.denseDepths);
    if (gl_LocalInvocationIndex == 0u) {
      // Two passes for this batch for a while (denseRect).
      UintArray history = UintArray(frame.f.denseHistory);
      history.v[1u + pc.firstView + gl_WorkGroupID.x] = history.v[0];
      if (COUNT != 0u)
        atomicAdd(Uint64Array(frame.f.stats).v[(gl_WorkGroupID.x % kBatchStatSlots) * kBatchStatCount +
                                               kStatBatchesRedrawn], 1ul);
    }
  }
  endStats(frame.f.stats, kStatPointsBlended, blended, false, v.words, count);
}
