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

// The decision of the batch being drawn, handed from thread 0 to the workgroup.
shared BatchView sharedBatchView;

// The decision for batch `batch` of the part, the same bits in every thread. Thread 0 alone loads the bounds
// and runs viewBox (~300 instructions, ~3.7 a point when all 128 threads ran it: bench/NOTES.md, session 6);
// the others wait at the barrier, so every thread of the workgroup must call it, in uniform control flow.
BatchView viewBatch(uint batch, BatchCamera cam, uint forcedWords, bool culling) {
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
