#version 460
// LOD resolve: a pixel's visibility index names a point by its place in the pass's node order (points of the
// pass numbered node after node, nodes by key), so a binary search over the nodes' first indices finds its
// node, the node's pages its color. ResolvePush::aux is the LodFrame.
//   MODE 0: the image (and the canonical words) of a frame drawn in one pass
//   MODE 1: composes the pass into the per-pixel composite (shared.h, kLodCompositeBytes): the word
//           (depth, node rank, index in node) replaces the composite's if smaller, so the order across
//           passes is the order within one pass
//   MODE 2: the image (and canonical words) from the composite, after the last pass
#include "common.inc.glsl"
#include "grid.inc.glsl"
#include "lod_frame.inc.glsl"

layout(local_size_x = kPixelGroupSize) in;
layout(push_constant) uniform Push { ResolvePush pc; };
layout(constant_id = 0) const uint MODE = 0;

layout(buffer_reference, std430, buffer_reference_align = 16) buffer CompositeArray { uvec4 v[]; };

const uvec4 kEmptyComposite = uvec4(0xFFFFFFFFu);

void writePixel(uint i, bool empty, uint depthBits, uint color) {
  UintArray(pc.image).v[i] = empty ? pc.background : color;
  if (pc.words != 0ul)
    Uint64Array(pc.words).v[i] = empty ? kEmptyPixel : (uint64_t(depthBits) << 32) | uint64_t(color);
}

// Lexicographic a < b over (depth, rank, index in node); the color never decides.
bool before(uvec4 a, uvec4 b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

void main() {
  uint i = linearInvocation(pc.groupsX, kPixelGroupSize);
  if (i >= pc.width * pc.height) return;
  LodFrame f = LodFrameRef(pc.aux).f;
  if (MODE == 2u) {
    uvec4 c = CompositeArray(f.composite).v[i];
    writePixel(i, c == kEmptyComposite, c.x, c.w);
    return;
  }
  uint64_t word = Uint64Array(pc.framebuffer).v[i];
  bool empty = word == kEmptyPixel;
  uint depthBits = uint(word >> 32), color = 0u;
  uint node = 0u, local = 0u;
  if (!empty) {
    uint index = uint(word);
    // The last node whose first index is <= index (nodes hold at least one point each).
    LodNodes nodes = LodNodes(f.nodes);
    uint lo = 0u, hi = f.nodeCount;
    while (hi - lo > 1u) {
      uint mid = (lo + hi) / 2u;
      if (nodes.v[mid].firstIndex <= index) lo = mid;
      else hi = mid;
    }
    node = lo;
    LodNode n = nodes.v[node];
    local = index - n.firstIndex;
    LodPage page = LodPages(f.pages).v[n.firstPage + local / kLodPagePoints];
    color = UintArray(page.address + uint64_t(kLodPageColors)).v[local % kLodPagePoints];
    node = n.rank;
  }
  if (MODE == 0u) {
    writePixel(i, empty, depthBits, color);
    return;
  }
  if (empty) return;
  uvec4 mine = uvec4(depthBits, node, local, color);
  CompositeArray composite = CompositeArray(f.composite);
  if (before(mine, composite.v[i])) composite.v[i] = mine;
}
