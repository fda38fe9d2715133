// C++ view of shaders/shared.h with layout checks: if a member moves, this fails to compile instead of
// the GPU reading garbage.
#pragma once

#include <cstddef>

#include "shared.h"

namespace pointrast::shared {

static_assert(sizeof(RasterPush) == 128); // the push-constant size every device must support
static_assert(offsetof(RasterPush, positions) == 64);
static_assert(offsetof(RasterPush, framebuffer) == 80);
static_assert(offsetof(RasterPush, scene) == 96);
static_assert(offsetof(RasterPush, pointCount) == 104);
static_assert(offsetof(RasterPush, groupsX) == 120);
static_assert(sizeof(ResolvePush) == 56);
static_assert(offsetof(ResolvePush, int40Scale) == 48);
static_assert(sizeof(PostPush) == 64);
static_assert(offsetof(PostPush, width) == 24 && offsetof(PostPush, pointSize) == 48);
static_assert(offsetof(ResolvePush, width) == 32);
static_assert(sizeof(CopyPush) == 24);

// The 2022 batch passes: BatchPush is 128 bytes like RasterPush; BatchFrame and BatchBounds live in
// buffers read with std430 rules (uint64_t members at multiples of 8, vec4 at multiples of 16).
static_assert(sizeof(BatchPush) == 128);
static_assert(offsetof(BatchPush, high) == 64);
static_assert(offsetof(BatchPush, frame) == 104);
static_assert(offsetof(BatchPush, pointCount) == 112);
static_assert(offsetof(BatchPush, part) == 120);
static_assert(sizeof(BatchBounds) == 32);
static_assert(offsetof(BatchFrame, width) == 24);
static_assert(offsetof(BatchFrame, culling) == 36);
static_assert(offsetof(BatchFrame, eyes) == 44);
static_assert(offsetof(BatchFrame, partColors) == 48);
static_assert(offsetof(BatchFrame, rightViewProj) == 48 + 8 * kMaxVisibilityParts); // 16-aligned for std430
static_assert(offsetof(BatchFrame, views) == 48 + 8 * kMaxVisibilityParts + 64 * kMaxVisibilityParts);
static_assert(offsetof(BatchFrame, denseTiles) == 64 + 8 * kMaxVisibilityParts + 64 * kMaxVisibilityParts);
static_assert(sizeof(BatchFrame) == 96 + 8 * kMaxVisibilityParts + 64 * kMaxVisibilityParts);
static_assert(offsetof(BatchFrame, clips) == 88 + 8 * kMaxVisibilityParts + 64 * kMaxVisibilityParts);

// Clip volumes and the renderer's scene table (std430: vec4 arrays at multiples of 16).
static_assert(sizeof(ClipVolumes) == 3728 && offsetof(ClipVolumes, box) == 16);
static_assert(offsetof(ClipVolumes, vertices) ==
              16 + 16 * (2 * kMaxClipBoxes + 4 * kMaxClipOrientedBoxes + kMaxClipPolygons));
static_assert(kSceneMatrixOffset >= sizeof(ClipVolumes) && kSceneMatrixOffset % 128 == 0 &&
              kSceneRecordBytes == kSceneMatrixOffset + 128 && kSceneTableHeader == 8 * kMaxVisibilityParts);
static_assert(kBatchPoints == 10240 && kBatchPrefetchSteps * 4 == kBatchPointsPerThread);
static_assert(uint64_t(kMaxPartBatches) * kBatchPoints <= kVisibilityLocalMask + 1ull);
static_assert(uint64_t(kMaxVisibilityParts) << kVisibilityPartShift == 1ull << 32);

// The LOD passes: LodNode, LodPage, LodNodeView and LodFrame live in buffers read with std430 rules; LodPush
// is a push-constant block.
static_assert(sizeof(LodNode) == 48 && offsetof(LodNode, firstIndex) == 32 && offsetof(LodNode, rank) == 44);
static_assert(sizeof(LodPage) == 16 && offsetof(LodPage, node) == 8);
static_assert(sizeof(LodNodeView) == 96);
static_assert(sizeof(LodFrame) == 176 && offsetof(LodFrame, clip) == 160 && offsetof(LodFrame, width) == 56 &&
              offsetof(LodFrame, pageCount) == 76 && offsetof(LodFrame, eyes) == 88 &&
              offsetof(LodFrame, rightViewProj) == 96);
static_assert(sizeof(LodPush) == 80 && offsetof(LodPush, frame) == 64 && offsetof(LodPush, groupsX) == 76);
static_assert(kLodPageSteps * 4 * kPointGroupSize == kLodPagePoints && kLodPagePoints % 4 == 0);

// Spheres: SphereFrame lives in a buffer read with std430 rules (struct alignment 16 for its mat4/vec4).
static_assert(sizeof(SphereFrame) == 240);
static_assert(offsetof(SphereFrame, batchBounds) == 176 && offsetof(SphereFrame, batches) == 208);
static_assert(kSphereBatchSize == kSphereGroupSize && kSphereCoarseTiles == 1u << kSphereCoarseShift &&
              kSphereFineSide == 1u << kSphereFineShift && kSphereFinePerTile * kSphereFineSide == kSphereTileSide);
static_assert(offsetof(SphereFrame, pixelToRay) == 64);
static_assert(offsetof(SphereFrame, framebuffer) == 80);
static_assert(offsetof(SphereFrame, image) == 104);
static_assert(offsetof(SphereFrame, width) == 112);
static_assert(offsetof(SphereFrame, background) == 140);
static_assert(offsetof(SphereFrame, counters) == 144);
static_assert(offsetof(SphereFrame, tileBounds) == 160);
static_assert(kSphereTileSide == 1u << kSphereTileShift &&
              kSphereChunkPixels == kSphereTileSide * kSphereTileSide);
static_assert(sizeof(SpherePartRef) == 16);
static_assert(sizeof(SpherePush) == 32);
static_assert(offsetof(SpherePush, first) == 16);
static_assert(offsetof(SpherePush, firstGroup) == 28);
static_assert(sizeof(SphereAabbPush) == 32);
static_assert(offsetof(SphereAabbPush, count) == 24);
static_assert(sizeof(SphereRtPush) == 24 && offsetof(SphereRtPush, pieceParticles) == 16);
static_assert(kSphereTaskSpheres % kSphereTaskGroupSize == 0 && kSphereTaskGroupSize <= 32); // one mask word

static_assert(sizeof(PresentPush) == 24 && offsetof(PresentPush, targetHeight) == 20);
static_assert(sizeof(PanelPush) == 56 && offsetof(PanelPush, firstIndex) == 24 &&
              offsetof(PanelPush, scaleY) == 44 && offsetof(PanelPush, image) == 48);

} // namespace pointrast::shared
