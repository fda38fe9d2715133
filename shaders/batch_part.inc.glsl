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

uint64_t boxClip() {
  return Uint64Array(FrameRef(pc.frame).f.clips).v[pc.part];
}

// Where the decision of batch `batch` of the part for eye `eye` is in BatchFrame::views.
uint viewIndex(uint batch, uint eye, uint eyes) {
  return (pc.firstView + batch) * eyes + eye;
}

// The decision (culling, precision, the folded screen map) of batch `batch` of the part for eye `eye`:
// batch_views.comp computed every batch's before the drawing passes, so a workgroup reads its own with one
// load. (Computed in the workgroup instead, by one thread between two barriers, the batch kernel was 2.3 %
// slower on the H200: docs/performance.md.)
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

// batch-hqs's dense batches: depth and blending in one pass (raster_batch_hqs_dense.comp), then only their points
// on pixels found wrong blended again. The batch `batch` of the part (decision v, for camera cam) is dense if
// it has one coordinate word, lies inside the image, is full, has at least kHqsDenseRatio points per pixel of
// its pixel rectangle, and was not drawn again in the last kHqsDenseRetry frames or so (its points then lay
// behind closer ones: most likely they still do, and two passes cost less). Returns that rectangle
// (boxPixelRect), or x = -1 for a batch that is not dense. Computed once per batch by batch_views.comp
// (BatchView::rect).
vec4 denseRect(BatchView v, BatchCamera cam, uint batch) {
  FrameRef frame = FrameRef(pc.frame);
  if (frame.f.dense == 0u || v.words != 1u || (batch + 1u) * kBatchPoints > pc.pointCount) return vec4(-1.0);
  UintArray history = UintArray(frame.f.denseHistory);
  uint index = pc.firstView + batch, redrawn = history.v[1u + index];
  if (redrawn != 0u && history.v[0] - redrawn < kHqsDenseRetry + index % kHqsDenseRetry) return vec4(-1.0);
  vec4 r = boxPixelRect(v, cam);
  if (r.x < 0.0) return r;
  float area = (r.z - r.x + 1.0) * (r.w - r.y + 1.0);
  return area * float(kHqsDenseRatio) <= float(kBatchPoints) ? r : vec4(-1.0);
}

// Whether batch-hqs draws a batch (its decision v) as a dense one: it is (denseRect), the frame lets it, the
// frame is mono and the subgroups are full (the dense pass splits the batch by subgroup). Uniform in a
// workgroup. Needs GL_KHR_shader_subgroup_basic.
bool denseBatch(BatchView v) {
  if (STEREO != 0u || v.rect.x < 0.0) return false;
  return FrameRef(pc.frame).f.dense != 0u && gl_NumSubgroups * gl_SubgroupSize == kPointGroupSize;
}
