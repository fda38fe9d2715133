#version 460
// lod-hqs, accumulation pass: after the depth pass (raster_lod.comp with DEPTH_ONLY) of every pass of the
// frame, one workgroup per page blends the page's points within 1 % of their pixel's closest depth with the
// single packed atomic and its overflow fallback (batch_blend.inc.glsl, hqs_accumulate.inc.glsl).
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_EXT_control_flow_attributes : require
#include "lod.inc.glsl"
#include "hqs_accumulate.inc.glsl"
#include "batch_blend.inc.glsl"

void main() {
  beginStats();
  LodFrame f = LodFrameRef(pc.frame).f;
  uint index = lodWorkgroup();
  uint blended = 0u;
  if (index < f.pageCount) { // uniform over the workgroup
    LodPage page = LodPages(f.pages).v[index];
    LodNode node = LodNodes(f.nodes).v[page.node];
    BatchView v = loadView(LodViews(f.views).v[page.node]);
    uint count = min(kLodPagePoints, node.pointCount - page.first);
    if (STEREO != 0u) {
      BatchView right = loadView(LodViews(f.views).v[f.nodeCount + page.node]);
      blended = blendBoxStereo(v, right, pageWords(page.address), count, kLodPageSteps, lodCamera(f, 0u),
                               lodCamera(f, 1u), f.framebuffer, f.accumulators);
    } else {
      blended = blendBox(v, pageWords(page.address), count, kLodPageSteps, lodCamera(f, 0u), f.framebuffer,
                         f.accumulators, 0ul);
    }
  }
  endStats(f.stats, kStatPointsBlended, blended, false, 0u, 0u);
}
