#version 460
// lod (and lod-hqs's depth pass, DEPTH_ONLY): one workgroup per page of a node of the pass draws the page's
// points with the batch methods' loop (batch_draw.inc.glsl), through the node's box decision from the node
// pass. A point's visibility index is its node's firstIndex + its index in the node: points numbered in
// node-key order, whatever pages of the node cache hold them.
#include "lod.inc.glsl"

layout(constant_id = 0) const uint PREFETCH = 1;
layout(constant_id = 1) const uint DEPTH_ONLY = 0;
const uint EARLY_HIGH = 0u; // the node's decision is one load, from the node pass

#include "batch_draw.inc.glsl"

void main() {
  beginStats();
  LodFrame f = LodFrameRef(pc.frame).f;
  uint index = lodWorkgroup();
  uint rendered = 0u;
  if (index < f.pageCount) { // uniform over the workgroup
    LodPage page = LodPages(f.pages).v[index];
    LodNode node = LodNodes(f.nodes).v[page.node];
    BatchView v = loadView(LodViews(f.views).v[page.node]);
    uint count = min(kLodPagePoints, node.pointCount - page.first);
    if (STEREO != 0u) {
      BatchView right = loadView(LodViews(f.views).v[f.nodeCount + page.node]);
      rendered = drawBoxAsStereo(v, right, pageWords(page.address), node.firstIndex + page.first, count,
                                 kLodPagePoints, kLodPageSteps, lodCamera(f, 0u), lodCamera(f, 1u), f.framebuffer);
    } else {
      rendered = drawBoxAs(v, pageWords(page.address), node.firstIndex + page.first, count, kLodPagePoints,
                           kLodPageSteps, lodCamera(f, 0u), f.framebuffer);
    }
  }
  endStats(f.stats, kStatPointsRendered, rendered, false, 0u, 0u);
}
