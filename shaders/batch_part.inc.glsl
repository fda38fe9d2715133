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

// 1: the frame's decisions were computed by batch_views.comp before the pass (BatchFrame::views) and a
// workgroup reads its batch's with one load; 0: thread 0 computes it and hands it to the workgroup through
// shared memory, between two barriers (kept only to time the difference: method rows batch-prefetch-shared*).
layout(constant_id = 4) const uint VIEW_PASS = 1;

layout(buffer_reference, std430, buffer_reference_align = 16) buffer BatchViews { LodNodeView v[]; };

// The decision of the batch being drawn, handed from thread 0 to the workgroup (VIEW_PASS 0).
shared BatchView sharedBatchView;

// Where the decision of batch `batch` of the part for eye `eye` is in BatchFrame::views.
uint viewIndex(uint batch, uint eye, uint eyes) {
  return (pc.firstView + batch) * eyes + eye;
}

// The decision for batch `batch` of the part, the same bits in every thread: read from the view pass's
// buffer, or (VIEW_PASS 0) computed by thread 0 alone (~300 instructions, ~3.7 a point when all 128 threads
// ran it: bench/NOTES.md, session 6) while the others wait at the barrier, so that every thread of the
// workgroup must then call it, in uniform control flow.
BatchView viewBatch(uint batch, BatchCamera cam, uint forcedWords, bool culling) {
  if (VIEW_PASS != 0u) {
    FrameRef frame = FrameRef(pc.frame);
    uint eye = cam.offset != 0u ? 1u : 0u; // batchCamera: the right eye's image is the half at offset width
    return loadView(BatchViews(frame.f.views).v[viewIndex(batch, eye, frame.f.eyes)]);
  }
  barrier(); // a previous call's readers are done with sharedBatchView (the stereo passes call it twice)
  if (gl_LocalInvocationIndex == 0u) {
    BatchBounds bounds = BoundsArray(pc.bounds).v[batch];
    sharedBatchView = viewBox(bounds.min.xyz, bounds.max.xyz, cam, forcedWords, culling);
  }
  barrier();
  return sharedBatchView;
}

// Where the points of the batch starting at point `first` of the part are (a multiple of 10240, so the
// addresses stay 16-byte aligned).
BatchWords batchWords(uint first) {
  uint64_t offset = uint64_t(first) * 4ul;
  return BatchWords(pc.high + offset, pc.medium + offset, pc.low + offset, pc.colors + offset);
}
