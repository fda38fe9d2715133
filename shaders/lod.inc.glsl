// The LOD passes (shared.h, "Level of detail"): a frame's list of nodes and pages and the per-node box
// decisions, around batch.inc.glsl's functions of a box of quantized points.
#include "batch.inc.glsl"
#include "lod_frame.inc.glsl"

layout(push_constant) uniform Push { LodPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) buffer LodViews { LodNodeView v[]; };

BatchCamera lodCamera(LodFrame f) {
  BatchCamera cam;
  cam.viewProj = pc.viewProj;
  cam.nearW = pc.nearW;
  cam.width = f.width;
  cam.height = f.height;
  return cam;
}

// The workgroup's index in the 2D grid of the dispatch.
uint lodWorkgroup() {
  return gl_WorkGroupID.y * pc.groupsX + gl_WorkGroupID.x;
}

LodNodeView storeView(BatchView v) {
  return LodNodeView(vec4(v.cx, uintBitsToFloat(v.words)), vec4(v.cy, v.inside ? 1.0 : 0.0), vec4(v.cz, 0.0),
                     vec4(v.offset, 0.0), vec4(v.lo, 0.0), vec4(v.step, 0.0));
}

BatchView loadView(LodNodeView s) {
  BatchView v;
  v.words = floatBitsToUint(s.cx.w);
  v.inside = s.cy.w != 0.0;
  v.cx = s.cx.xyz;
  v.cy = s.cy.xyz;
  v.cz = s.cz.xyz;
  v.offset = s.offset.xyz;
  v.lo = s.lo.xyz;
  v.step = s.step.xyz;
  return v;
}

// Where the points of a page are: its four sections.
BatchWords pageWords(uint64_t address) {
  return BatchWords(address, address + uint64_t(kLodPageSectionBytes), address + 2ul * kLodPageSectionBytes,
                    address + uint64_t(kLodPageColors));
}
