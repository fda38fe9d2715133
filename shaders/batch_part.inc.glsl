// The batches of a part (the batch methods' scene layout, render/scene.h): one dispatch draws one part,
// one workgroup per batch of 10240 consecutive points (BatchPush pc), whose box and words batch.inc.glsl
// decodes.
#include "batch.inc.glsl"

layout(push_constant) uniform Push { BatchPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer BoundsArray {
  BatchBounds v[];
};
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer FrameRef { BatchFrame f; };

// The camera of eye `eye` (0: the left, or the only one; 1: the right of a stereo frame), read field by field
// (the frame holds the table of colors and matrices besides).
BatchCamera batchCamera(FrameRef frame, uint eye) {
  BatchCamera cam;
  cam.viewProj = eye == 0u ? pc.viewProj : frame.f.rightViewProj[pc.part];
  cam.nearW = pc.nearW;
  cam.width = frame.f.width;
  cam.height = frame.f.height;
  cam.pitch = frame.f.pitch;
  cam.offset = eye * frame.f.width;
  return cam;
}

layout(buffer_reference, std430, buffer_reference_align = 16) buffer BatchViews { LodNodeView v[]; };

// Where the decision of batch `batch` of the part for eye `eye` is in BatchFrame::views.
uint viewIndex(uint batch, uint eye, uint eyes) {
  return (pc.firstView + batch) * eyes + eye;
}

// The decision (culling, precision, the folded screen map) of batch `batch` of the part for eye `eye`:
// batch_views.comp computed every batch's before the drawing passes, so a workgroup reads its own with one
// load. (Computed in the workgroup instead, by one thread between two barriers, the batch kernel was 2.3 %
// slower on the H200: bench/NOTES.md, session 7.)
BatchView viewBatch(uint batch, uint eye) {
  FrameRef frame = FrameRef(pc.frame);
  return loadView(BatchViews(frame.f.views).v[viewIndex(batch, eye, frame.f.eyes)]);
}

// Where the points of the batch starting at point `first` of the part are (a multiple of 10240, so the
// addresses stay 16-byte aligned).
BatchWords batchWords(uint first) {
  uint64_t offset = uint64_t(first) * 4ul;
  return BatchWords(pc.high + offset, pc.medium + offset, pc.low + offset, pc.colors + offset);
}

// Whether batch-hqs draws the batch (its decision v, `count` points) as a dense one: depth and blending in
// one pass (raster_batch_hqs_dense.comp), then only its points on pixels found wrong blended again. Dense:
// one coordinate word, inside the image, full, at least kHqsDenseRatio points per pixel of its pixel
// rectangle, and full subgroups (the dense pass splits the batch by subgroup). Uniform in a workgroup.
// Needs GL_KHR_shader_subgroup_basic.
bool denseBatch(BatchView v, uint count) {
  if (STEREO != 0u || v.words != 1u || !v.inside || count != kBatchPoints || v.rect.x < 0.0) return false;
  if (FrameRef(pc.frame).f.dense == 0u || gl_NumSubgroups * gl_SubgroupSize != kPointGroupSize) return false;
  float area = (v.rect.z - v.rect.x + 1.0) * (v.rect.w - v.rect.y + 1.0);
  return area * float(kHqsDenseRatio) <= float(count);
}
