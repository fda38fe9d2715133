// The batches of a part (the batch methods' scene layout, render/scene.h): one dispatch draws one part,
// one workgroup per batch of 10240 consecutive points (BatchPush pc), whose box and words batch.inc.glsl
// decodes.
#include "batch.inc.glsl"

layout(push_constant) uniform Push { BatchPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer BoundsArray {
  BatchBounds v[];
};
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer FrameRef { BatchFrame f; };

BatchCamera batchCamera(BatchFrame f) {
  BatchCamera cam;
  cam.viewProj = pc.viewProj;
  cam.nearW = pc.nearW;
  cam.width = f.width;
  cam.height = f.height;
  return cam;
}

// The decision for batch `batch` of the part.
BatchView viewBatch(uint batch, BatchCamera cam, uint forcedWords, bool culling) {
  BatchBounds bounds = BoundsArray(pc.bounds).v[batch];
  return viewBox(bounds.min.xyz, bounds.max.xyz, cam, forcedWords, culling);
}

// Where the points of the batch starting at point `first` of the part are (a multiple of 10240, so the
// addresses stay 16-byte aligned).
BatchWords batchWords(uint first) {
  uint64_t offset = uint64_t(first) * 4ul;
  return BatchWords(pc.high + offset, pc.medium + offset, pc.low + offset, pc.colors + offset);
}
