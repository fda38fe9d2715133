#version 460
// LOD, node pass: one thread per node of the pass computes the node's box decision (frustum culling,
// coordinate words, screen map: batch.inc.glsl's viewBox on the node's tight bounds) once, for every page
// of the node to read; and counts nodes processed and rendered and their points by coordinate words.
#include "lod.inc.glsl"

void main() {
  LodFrame f = LodFrameRef(pc.frame).f;
  uint i = lodWorkgroup() * kPointGroupSize + gl_LocalInvocationIndex;
  if (i >= f.nodeCount) return;
  LodNode node = LodNodes(f.nodes).v[i];
  BatchView v = viewBox(node.min.xyz, node.max.xyz, lodCamera(f, 0u), f.forcedWords, f.culling != 0u);
  bool clipped;
  v = clipView(v, node.min.xyz, node.max.xyz, clipped);
  LodViews(f.views).v[i] = storeView(v);
  uint words = v.words;
  if (STEREO != 0u) {
    // The right eye's decision after every left one; a node is read once, with the words either eye needs.
    BatchView right = viewBox(node.min.xyz, node.max.xyz, lodCamera(f, 1u), f.forcedWords, f.culling != 0u);
    bool rightClipped;
    right = clipView(right, node.min.xyz, node.max.xyz, rightClipped);
    LodViews(f.views).v[f.nodeCount + i] = storeView(right);
    words = max(words, right.words);
    clipped = (clipped || rightClipped) && words == 0u;
  }
  if (f.nodeStats == 0u) return;
  Uint64Array stats = Uint64Array(f.stats);
  uint row = (i % kBatchStatSlots) * kBatchStatCount;
  atomicAdd(stats.v[row + kStatBatchesProcessed], 1ul);
  if (clipped) atomicAdd(stats.v[row + kStatBatchesClipped], 1ul);
  if (words == 0u) return;
  atomicAdd(stats.v[row + kStatBatchesRendered], 1ul);
  atomicAdd(stats.v[row + kStatPointsOneWord + words - 1u], uint64_t(node.pointCount));
}
