// The LOD passes (shared.h, "Level of detail"): a frame's list of nodes and pages and the per-node box
// decisions, around batch.inc.glsl's functions of a box of quantized points.
#include "batch.inc.glsl"
#include "lod_frame.inc.glsl"

layout(push_constant) uniform Push { LodPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) buffer LodViews { LodNodeView v[]; };

uint64_t boxClip() {
  return LodFrameRef(pc.frame).f.clip;
}

// The camera of eye `eye` (0: the left, or the only one; 1: the right of a stereo frame).
BatchCamera lodCamera(LodFrame f, uint eye) {
  BatchCamera cam;
  cam.viewProj = eye == 0u ? pc.viewProj : f.rightViewProj;
  cam.nearW = pc.nearW;
  cam.width = f.width;
  cam.height = f.height;
  cam.pitch = f.pitch;
  cam.offset = eye * f.width;
  return cam;
}

// The workgroup's index in the 2D grid of the dispatch.
uint lodWorkgroup() {
  return gl_WorkGroupID.y * pc.groupsX + gl_WorkGroupID.x;
}

// Where the points of a page are: its four sections.
BatchWords pageWords(uint64_t address) {
  return BatchWords(address, address + uint64_t(kLodPageSectionBytes), address + 2ul * kLodPageSectionBytes,
                    address + uint64_t(kLodPageColors));
}
