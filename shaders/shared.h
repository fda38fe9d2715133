// The one definition of every struct and constant shared by C++ and GLSL. C++ includes it through
// gpu/shared_types.h, which static_asserts sizes and offsets; shaders include it directly.
//
// Push-constant blocks use std430 rules (GLSL's default for push constants): 8-byte members sit at
// multiples of 8, a mat4 is 64 bytes; the C++ side mirrors the order so no hand padding is needed.
#ifndef POINTRAST_SHARED_H
#define POINTRAST_SHARED_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
#define PR_NAMESPACE_BEGIN namespace pointrast::shared {
#define PR_NAMESPACE_END }
#define PR_CONST constexpr uint32_t
#define PR_CONST64 constexpr uint64_t
PR_NAMESPACE_BEGIN
using uint = uint32_t;
using mat4 = glm::mat4;
using vec4 = glm::vec4;
using uvec2 = glm::uvec2;
PR_NAMESPACE_END
#else
#define PR_NAMESPACE_BEGIN
#define PR_NAMESPACE_END
#define PR_CONST const uint
#define PR_CONST64 const uint64_t
#endif

PR_NAMESPACE_BEGIN

// Threads per workgroup of the point kernels: 128 = 4 NVIDIA warps or 2 AMD wave64s; the 2022 batch
// layout (128 threads x 80 points) keeps the same width.
PR_CONST kPointGroupSize = 128;
// Threads per workgroup of per-pixel passes (resolve/clear): 256, a multiple of every subgroup size.
PR_CONST kPixelGroupSize = 256;

// Framebuffer word of the closest-point methods: depth in the high 32 bits (IEEE bits of the linear view
// depth c.w, which is > 0 and so orders like an unsigned integer), payload in the low 32 bits (RGBA8).
// An empty pixel holds all ones, which no point's word can reach (NaN depth bits are never written).
PR_CONST64 kEmptyPixel = 0xFFFFFFFFFFFFFFFFul;

// ------------------------------------------------------------------------------------------------------
// Clip volumes (cloud/point_filter.h, the same rules): a point is inside when it lies in at least one box,
// oriented box or polygon prism (boundaries inside), and kept by mode kClipInside when inside, by
// kClipOutside when not. Coordinates are relative to the scene origin, rounded once to float from the
// filter's doubles (render/clip_volumes.h). The renderer writes one ClipVolumes per scene a frame; every point
// method tests each point from the position it loads, and the batch and LOD methods first decide whole
// batches and nodes (clip.inc.glsl, clipBoxVerdict): drawn without a test, culled, or tested point by point.
// ------------------------------------------------------------------------------------------------------
PR_CONST kClipNone = 0;    // no clip volume: every point is kept, nothing is read beyond `mode`
PR_CONST kClipInside = 1;  // keep the points inside the union of the volumes
PR_CONST kClipOutside = 2; // keep the others
// Volumes a frame can hold: 16 boxes (32 B each) + 16 oriented boxes (64 B) + 8 polygons (16 B) of 256
// vertices in all (8 B), 3.7 KB, read through the cache by every thread.
PR_CONST kMaxClipBoxes = 16;
PR_CONST kMaxClipOrientedBoxes = 16;
PR_CONST kMaxClipPolygons = 8;
PR_CONST kMaxClipVertices = 256;

struct ClipVolumes {
  uint mode;      // kClipNone, kClipInside, kClipOutside
  uint boxes;     // axis-aligned boxes: box[2 i] min, box[2 i + 1] max (w unused)
  uint orientedBoxes; // oriented[4 i] the center, then the three unit axes with the half extent
                  // along each in w: inside when |dot(axis, p - center)| <= w for all three
  uint polygons;  // polygon prisms: polygon[i] = (first vertex, vertex count as uint bits, zMin, zMax);
                  // vertices two to a vec4 (x0, y0, x1, y1); even-odd rule in x/y, zMin <= z <= zMax
  vec4 box[2 * kMaxClipBoxes];
  vec4 oriented[4 * kMaxClipOrientedBoxes];
  vec4 polygon[kMaxClipPolygons];
  vec4 vertices[kMaxClipVertices / 2];
};

// The renderer's per-frame table (Targets::scenes): the ClipVolumes address of each visibility part's scene
// (the batch passes find it by BatchPush::part), then one record per scene of kSceneRecordBytes: its
// ClipVolumes, then at kSceneMatrixOffset its view-projection in double precision (a dmat4, the int40 path).
PR_CONST kSceneMatrixOffset = 3840;  // sizeof(ClipVolumes) = 3728, rounded up to a multiple of 128
PR_CONST kSceneRecordBytes = 3968;   // + 128 B of dmat4
PR_CONST kSceneTableHeader = 512;    // uint64_t[kMaxVisibilityParts]
// Bit 0 of RasterPush::scene: the scene's clip volumes drop points (mode kClipInside or kClipOutside). Without
// it a point method tests nothing and reads nothing more than without clip volumes.
PR_CONST64 kSceneClipped = 1ul;

// Push constants of the point rasterizers: one dispatch draws one part of a scene (a range of points
// living in one buffer pair), addressed by buffer device address so parts may be anywhere in memory and
// scenes may exceed the 4 GiB range of a storage-buffer descriptor. 128 bytes: the minimum every Vulkan
// device must allow.
struct RasterPush {
  mat4 viewProj;         // world-relative-to-origin -> clip; only rows x, y, w are used
  uint64_t positions;    // address of float[3 * pointCount]
  uint64_t colors;       // address of uint[pointCount] (RGBA8)
  uint64_t framebuffer;  // address of the method's framebuffer (uint64_t per pixel for most methods)
  uint64_t aux;          // method-specific buffer (HQS accumulators), 0 if none
  uint64_t scene;        // address of the scene's record: ClipVolumes, then at kSceneMatrixOffset the same
                         // matrix in double precision (a dmat4, int40 depth); records are 128-byte aligned,
                         // and bit 0 (kSceneClipped) is set when the clip volumes drop points

  uint pointCount;
  uint width;
  uint height;
  float nearW;           // points with c.w <= nearW are dropped
  uint groupsX;          // workgroups per row of a 2D dispatch (a 1D grid may not exceed 65535 groups)
  float depthScale;      // int40 depth: integer steps per unit of linear depth (1000: millimetres)
};

// Push constants of the resolve passes (framebuffer -> RGBA8 image, and optionally canonical words).
struct ResolvePush {
  uint64_t framebuffer; // the method's framebuffer
  uint64_t image;       // uint[width * height], RGBA8, row 0 = top
  uint64_t aux;         // method-specific (HQS accumulators)
  uint64_t words;       // if not 0: uint64_t[width * height] receives depth << 32 | color per pixel
  uint width;
  uint height;
  uint background;      // RGBA8 written where no point landed
  uint groupsX;         // workgroups per row of the 2D dispatch
  float int40Scale;     // int40 depth: if > 0, words carry floatBits(steps / int40Scale) << 32 | RGBA8, the
                        // float-depth words the resolve stage reads; 0: the method's canonical words
  uint reserved;
};

// ------------------------------------------------------------------------------------------------------
// The resolve stage (src/render/post): passes that run after any point method's raster and resolve, on
// one float-depth word per pixel (floatBits(linear depth) << 32 | RGBA8, kEmptyPixel where empty) that
// every method's resolve writes (ResolvePush::words).
//   splat   points larger than one pixel: each pixel takes the smallest word among the pixels whose
//           point's square or disc covers it (the same image as rasterizing the shapes with atomicMin)
//   dilate  depth-aware hole filling: a pixel that is empty, or farther than the closer points of its
//           window, takes the closest of them when it lies within their convex hull
//   compose eye-dome lighting (optional), background, RGBA8 image and the final words
// ------------------------------------------------------------------------------------------------------

// Workgroups of the post passes are 16 x 16 pixel tiles (256 threads, like kPixelGroupSize), so a window
// of neighbours is mostly shared between the threads of a tile.
PR_CONST kPostTile = 16;
// Largest point side in pixels (fixed or attenuated): the splat pass reads up to 33 x 33 words a pixel.
PR_CONST kMaxPointSize = 32;
// Largest dilation radius: a 17 x 17 window (the 2022 paper's periphery uses 7 x 7, radius 3).
PR_CONST kMaxDilateRadius = 8;
// Splat shapes (specialization constant SHAPE of post_splat.comp).
PR_CONST kPointShapeSquare = 0; // side n: offsets -((n - 1) / 2) .. n / 2 from the point's pixel
PR_CONST kPointShapeDisc = 1;   // diameter s: pixels whose center is within s / 2 of the point's pixel center
// A pixel counts as a hole the dilation fills when the closer point is nearer by more than this factor
// (1 %, the HQS tolerance): surfaces seen at a slant differ less than that from one pixel to the next.
#define PR_DILATE_DEPTH_FACTOR 1.01
// Eye-dome lighting as Potree computes it (edl.fs): for a pixel with a point, response = the sum over 8
// neighbours at `radius` pixels (directions k * 45 degrees, nearest pixel) that hold a point of
// max(0, log2(depth) - log2(neighbour depth)), divided by 8; the color is scaled by
// shade = exp(-response * PR_EDL_EXPONENT * strength). Empty pixels keep the background.
#define PR_EDL_EXPONENT 300.0
PR_CONST kEdlNeighbours = 8;

// Push constants of the post passes. Buffers are addressed by device address and may be strided (an eye
// of a side-by-side stereo image is a window of a wider buffer: pitch > width).
struct PostPush {
  uint64_t source;  // uint64_t words, sourcePitch per row
  uint64_t target;  // splat, dilate: uint64_t words; compose: RGBA8 image; targetPitch per row
  uint64_t words;   // compose: if not 0, receives the final words (targetPitch per row)
  uint width;
  uint height;
  uint sourcePitch; // elements per row
  uint targetPitch;
  uint radius;      // splat: the window's reach, pixels; dilate: the window radius
  uint background;  // compose: RGBA8 where no point landed
  float pointSize;  // splat fixed: side (square) or diameter (disc) in pixels; attenuated: the same at
                    // linear depth 1 (the size at depth d is pointSize / d, clamped to [1, maxPointSize])
  float maxPointSize;
  float edlStrength; // compose: 0 = no eye-dome lighting
  float edlRadius;   // pixels
};

// Push constants of the shader copy that measures the device's copy bandwidth (src/gpu/bandwidth.cpp).
struct CopyPush {
  uint64_t source;      // uvec4[count]
  uint64_t destination; // uvec4[count]
  uint count;           // 16-byte elements
  uint groupsX;
};

// Word layout of the int40 depth encoding (the 2019 poster): 40-bit integer depth << 24 | 24-bit RGB.
PR_CONST kInt40ColorBits = 24;
PR_CONST64 kInt40MaxDepth = 0xFFFFFFFFFFul; // 2^40 - 1 steps: 1,099 km at 1 mm per step

// Busy-loop method: the framebuffer is two uint arrays (depth bits, then color); the top bit of a depth
// word is the pixel's lock (linear depth is a positive float, so its sign bit is free).
PR_CONST kPixelLockBit = 0x80000000u;
PR_CONST kEmptyDepthBits = 0x7FFFFFFFu; // above every finite positive float

// High-quality splatting (2019): a point is blended into its pixel if its linear depth is within 1 % of
// the closest point's.
#define PR_HQS_DEPTH_FACTOR 1.01
// batch-hqs draws a batch in one pass (depth and blending together, then a per-pixel check) when it is
// dense: one coordinate word, inside the image, full, at least kHqsDenseRatio points per pixel of its pixel
// rectangle, and not drawn again in the last kHqsDenseRetry frames or so (batch_part.inc.glsl, denseRect).
// kHqsDenseFlagged marks a pixel whose first-pass sums were dropped (hqs_dense_check.comp).
PR_CONST kHqsDenseRatio = 8;
PR_CONST kHqsDenseTile = 16;
PR_CONST kHqsDenseFlagged = 0xFFFFFFFFu;
PR_CONST kHqsDenseRetry = 32;
// hqs1r: one 64-bit word per pixel packs r, g, b, count in 16 bits each. 255 points of 255 sum to 65025,
// below 2^16, so a pixel stays exact up to 255 points; later points go to 32-bit fallback sums.
PR_CONST kHqs1rMaxCount = 255;

// ------------------------------------------------------------------------------------------------------
// The 2022 batched rasterizer: Schuetz, Kerbl, Wimmer, "Software Rasterization of 2 Billion Points in Real
// Time" (2022). One workgroup per batch of consecutive points; per-batch frustum culling and coordinate
// precision; a visibility buffer (depth << 32 | point index) resolved to colors afterwards.
// ------------------------------------------------------------------------------------------------------

// 128 threads x 80 points = 10240 points per batch (src/cloud/batch.h: kBatchSize).
PR_CONST kBatchPointsPerThread = 80;
PR_CONST kBatchPoints = kPointGroupSize * kBatchPointsPerThread;
// batch-prefetch: a thread loads the words of 4 consecutive points with one 128-bit load; 80 / 4 steps.
PR_CONST kBatchPrefetchSteps = kBatchPointsPerThread / 4;
// Quantized coordinates: 30 bits per axis relative to the batch bounds, 10 bits of each axis per word
// (src/cloud/batch_words.h); 2^30 - 1 is the largest.
PR_CONST kBatchWordBits = 10;
PR_CONST kBatchCoordinateMax = 0x3FFFFFFFu;

// Visibility index of a point: part << 26 | index of the point in its part, parts numbered over all
// scenes of a frame. A part holds at most 6553 batches x 10240 = 67,102,720 points < 2^26, and a frame at
// most 64 parts: 64 x 2^26 = 2^32 indices, 4.29 billion points per frame.
PR_CONST kVisibilityPartShift = 26;
PR_CONST kVisibilityLocalMask = 0x3FFFFFFu; // 2^26 - 1
PR_CONST kMaxPartBatches = 6553;
PR_CONST kMaxVisibilityParts = 64;

// Frame statistics: kBatchStatSlots rows of kBatchStatCount uint64 counters. A workgroup reduces its
// counts and adds them to row (workgroup id % 64), so 64 addresses share the atomics instead of one; the
// host sums the rows after the frame.
PR_CONST kBatchStatSlots = 64;
PR_CONST kBatchStatCount = 11;
PR_CONST kStatBatchesProcessed = 0; // workgroups that ran (every batch of every part)
PR_CONST kStatBatchesRendered = 1;  // batches not culled
PR_CONST kStatPointsRendered = 2;   // points that passed early-z and did the atomicMin
PR_CONST kStatPointsBlended = 3;    // batch-hqs: points blended into their pixel (within 1 % of closest)
PR_CONST kStatPointsOneWord = 4;    // points of rendered batches decoded from 1, 2, 3 words; their sum
PR_CONST kStatPointsTwoWords = 5;   // is the number of points processed
PR_CONST kStatPointsThreeWords = 6;
PR_CONST kStatBatchesDense = 7;    // batch-hqs: batches drawn in one pass (denseBatch)
PR_CONST kStatPointsTakenBack = 8; // batch-hqs: their points on flagged pixels, blended again
PR_CONST kStatBatchesRedrawn = 9;  // batch-hqs: dense batches the accumulation pass draws again
PR_CONST kStatBatchesClipped = 10; // batches (nodes) culled because no point of their box is kept by the clip

// Bounds of one batch relative to the scene origin, rounded once to float from the exact (double) bounds
// its points were quantized in. w is unused.
struct BatchBounds {
  vec4 min;
  vec4 max;
};

// What every batch pass reads about the frame. Copied into a device buffer at the start of each frame
// (it outgrows push constants), read through BatchPush::frame.
struct BatchFrame {
  uint64_t framebuffer;  // uint64_t per pixel: floatBits(depth) << 32 | visibility index; ones = empty
  uint64_t stats;        // uint64_t[kBatchStatSlots][kBatchStatCount]
  uint64_t accumulators; // batch-hqs: 1 packed + 2 fallback uint64_t per pixel, as hqs1r
  uint width;
  uint height;
  uint forcedWords; // 0: adaptive precision; 1..3: every batch decodes from this many words
  uint culling;     // 1: frustum culling; 0 (a debug setting): every batch is drawn
  uint pitch;       // pixels per framebuffer row: width, or 2 x width for a stereo frame (eyes side by side)
  uint eyes;        // 1, or 2: every point is drawn into the left half with BatchPush::viewProj and into the
                    // right half with rightViewProj[part] (specialization constant STEREO of the passes)
  uint64_t partColors[kMaxVisibilityParts]; // RGBA8 colors of visibility part p (the resolve's table)
  mat4 rightViewProj[kMaxVisibilityParts];  // stereo: the right half's view-projection of part p
  uint64_t views;    // LodNodeView per batch and eye of the frame, at (BatchPush::firstView + batch) * eyes
                     // + eye: the box decisions, written by batch_views.comp before the drawing passes
  // batch-hqs's dense batches (raster_batch_hqs_dense.comp): the farthest depth bits they blended per pixel
  // (uint per framebuffer pixel; kHqsDenseFlagged once hqs_dense_check.comp found the pixel wrong), and one
  // uint per kHqsDenseTile x kHqsDenseTile tile of the framebuffer, not 0 where a pixel of it is flagged.
  uint64_t denseDepths;
  uint64_t denseTiles;
  uint dense;  // 1: dense batches blend in the first pass; 0 (a debug setting): every batch takes two passes
  uint tilesX; // tiles per framebuffer row: pitch / kHqsDenseTile rounded up
  // uint: [0] the number of the last frame drawn with dense batches (hqs_dense_check.comp counts), then per
  // batch of the frame (BatchPush::firstView + batch) the number of the last frame that drew it again (0:
  // none). Such a batch is not dense for the next kHqsDenseRetry to 2 kHqsDenseRetry - 1 frames.
  uint64_t denseHistory;
  uint64_t clips; // uint64_t per visibility part: its scene's ClipVolumes (the scene table's header)
};

// Push constants of the batch passes: one dispatch draws one part, one workgroup per batch.
struct BatchPush {
  mat4 viewProj;   // world-relative-to-origin -> clip; only rows x, y, w are used
  uint64_t high;   // uint per point: bits 29..20 of x | y << 10 | z << 20; padded to a multiple of 4
  uint64_t medium; // bits 19..10, same layout and padding
  uint64_t low;    // bits 9..0
  uint64_t bounds; // BatchBounds per batch
  uint64_t colors; // uint per point, RGBA8 (read by batch-hqs for blended points only)
  uint64_t frame;  // BatchFrame
  uint pointCount; // points of the part
  float nearW;     // points with c.w <= nearW are dropped
  uint part;       // visibility part number of this part
  uint firstView;  // index of the part's first batch among the frame's batches (BatchFrame::views)
};

// ------------------------------------------------------------------------------------------------------
// Level of detail (the 2022 paper, sections 3.5-3.6): octree nodes drawn by the batch rasterizer. The GPU
// node cache (render/lod/) keeps nodes in pages of kLodPagePoints points; a frame draws a list of nodes (one
// LodNode each, ordered by node key) and one workgroup per page of them. A node's points are quantized to
// 30 bits per axis in its tight bounds exactly as a batch's are (cloud/batch_words.h).
// ------------------------------------------------------------------------------------------------------

// 128 threads x 32 points = 4096 points per page: a node of n points takes ceil(n / 4096) pages, so a node
// wastes half a page on average (6 % of a 16 k-point node) while a workgroup still has 8 steps of 4 points
// per thread to spread the load of its page's descriptor over.
PR_CONST kLodPagePoints = 4096;
PR_CONST kLodPageSteps = kLodPagePoints / (4 * kPointGroupSize); // steps of 4 points per thread: 8
// A page in GPU memory: four sections of kLodPagePoints uints: high, medium and low coordinate words
// (batch layout), then RGBA8 colors. 64 KiB.
PR_CONST kLodPageSectionBytes = kLodPagePoints * 4;
PR_CONST kLodPageBytes = 4 * kLodPageSectionBytes;

// One node of a pass, in the pass's node order (node keys ascending).
struct LodNode {
  vec4 min;        // tight bounds relative to the scene origin (w unused), rounded once to float from the
  vec4 max;        // exact bounds its points were quantized in
  uint firstIndex; // visibility index of the node's first point: points of the pass numbered in node order
  uint pointCount;
  uint firstPage;  // its first page in the pass's page list (a node's pages are consecutive there)
  uint rank;       // its position in the whole selection of the frame (the order across passes)
};

// One page of a pass: one workgroup of the drawing passes.
struct LodPage {
  uint64_t address; // the page in GPU memory (kLodPageBytes, sections as above)
  uint node;        // index of its node in the pass's node list
  uint first;       // index of its first point in the node (a multiple of kLodPagePoints)
};

// A node's box decision (batch.inc.glsl's BatchView), computed once per node and pass by lod_nodes.comp and
// read by every page of the node (a batch's likewise: batch_views.comp, BatchFrame::views): the screen map's
// rows (cx, cy, cz, offset), the min corner and the steps of the 30-bit quantization. cx.w holds the
// coordinate words (0: culled), cy.w 1 when every point of the box is inside the image (as float bits);
// cz.w, offset.w, lo.w, step.w the pixel rectangle its points can land on (first column, first row, last
// column, last row; cz.w < 0: not known), which batch_views.comp computes for batches and nodes leave at -1.
struct LodNodeView {
  vec4 cx;
  vec4 cy;
  vec4 cz;
  vec4 offset;
  vec4 lo;
  vec4 step;
};

// Per-pixel composition of several passes (a selection larger than the node cache, drawn in passes):
// uvec4 (depth bits, node rank, index in node, RGBA8), all ones = empty. The lexicographic minimum over the
// passes is the word one pass over the whole selection would have kept, whatever the split into passes.
PR_CONST kLodCompositeBytes = 16;

// What every LOD pass reads about the frame (a device buffer, like BatchFrame).
struct LodFrame {
  uint64_t framebuffer;  // uint64_t per pixel: floatBits(depth) << 32 | visibility index; ones = empty
  uint64_t stats;        // uint64_t[kBatchStatSlots][kBatchStatCount], batches meaning nodes
  uint64_t accumulators; // lod-hqs: hqs1r's layout
  uint64_t nodes;        // LodNode[nodeCount]
  uint64_t views;        // LodNodeView[nodeCount]
  uint64_t pages;        // LodPage[pageCount]
  uint64_t composite;    // uvec4 per pixel (kLodCompositeBytes)
  uint width;
  uint height;
  uint forcedWords; // 0: adaptive precision; 1..3: every node decodes from this many words
  uint culling;     // 1: frustum culling of nodes; 0 (a debug setting): every node is drawn
  uint nodeCount;
  uint pageCount;
  uint nodeStats; // 1: the node pass counts nodes and points (0 when a pass's nodes are viewed again)
  uint pitch;     // pixels per framebuffer row: width, or 2 x width for a stereo frame (eyes side by side)
  uint eyes;      // 1, or 2: views holds the right half's node decisions after the left's (views[nodeCount
                  // + i]), made with rightViewProj (specialization constant STEREO of the passes)
  uint reserved;
  mat4 rightViewProj; // stereo: the right half's view-projection (LodPush::viewProj is the left's)
  uint64_t clip;      // ClipVolumes of the octree (relative to its origin)
  uint64_t reserved2;
};

// Push constants of the LOD passes (a frame's matrix and near plane; the rest is in LodFrame).
struct LodPush {
  mat4 viewProj;  // world-relative-to-origin -> clip; only rows x, y, w are used
  uint64_t frame; // LodFrame
  float nearW;    // points with c.w <= nearW are dropped
  uint groupsX;   // workgroups per row of the 2D grid (pages or nodes may exceed 65535 workgroups)
};

// ------------------------------------------------------------------------------------------------------
// Spheres (particle sets): Gralka et al., "Efficient Sphere Rendering Revisited" (2023), ray-cast sphere
// impostors; sphere-compute rasterizes them in compute into the visibility-buffer word of the 2022 paper.
// ------------------------------------------------------------------------------------------------------

// GPU layouts of a particle part (one buffer each, named as in the 2023 study). `n` is the part's count.
//   soa8    8 float streams of n: x, y, z, r, R, G, B, A (color in [0, 1]), stream k at byte k * 4n
//   vec4x2  vec4 (x, y, z, r)[n], then vec4 (R, G, B, A)[n] at byte 16n
//   aos     { vec3 xyz; uint rgba8; }[n], 16 B; one global radius
//   xyz     float[3n]; one global radius and one global color
PR_CONST kSphereLayoutSoa8 = 0;
PR_CONST kSphereLayoutVec4x2 = 1;
PR_CONST kSphereLayoutAos = 2;
PR_CONST kSphereLayoutXyz = 3;

// Threads per workgroup of the per-sphere pass: one sphere per thread, as wide as the point kernels.
PR_CONST kSphereGroupSize = 128;
// A sphere whose clamped pixel box has at most 64 pixels (8 x 8) is ray-tested by its own thread; a larger
// one is cut into chunks for the large-sphere pass, so that a close-up does not serialize on one thread.
PR_CONST kSphereSmallPixels = 64;
// Large-sphere chunks, at most 256 pixels each, one pixel per thread of a 256-thread workgroup. A box of
// more than kSphereTileCutPixels pixels is cut along screen tiles of 16 x 16 pixels (tile (tx, ty) holds
// pixels [16 tx, 16 tx + 15] x [16 ty, 16 ty + 15]) clipped to the box, so that one depth bound per tile
// (SphereFrame::tileBounds) can skip a whole chunk with one comparison; a smaller one, which would
// straddle up to four tiles for a few hidden chunks, into bands of whole box rows (256 / width rows each).
PR_CONST kSphereTileShift = 4;
PR_CONST kSphereTileSide = 16;    // 1 << kSphereTileShift
PR_CONST kSphereChunkPixels = 256; // kSphereTileSide^2
PR_CONST kSphereTileCutPixels = 256; // a 16 x 16 box: one tile's area
// Occlusion culling in sphere-compute: the particles of a part in batches of kSphereBatchSize (one
// workgroup of the per-sphere pass), each with bounds computed once per particle set. A frame draws the
// batches visible in the last frame first, then builds a conservative depth pyramid from what they drew
// (16 x 16-pixel tiles and cells of kSphereCoarseTiles^2 tiles), tests every other batch's bounds against
// it and draws those that may show. The pyramid has 4 x 4-pixel cells too: a batch at long range covers a
// few pixels, and a tile's depth range over a slanted surface (tens of units) would keep many layers.
PR_CONST kSphereBatchSize = 128;        // kSphereGroupSize
PR_CONST kSphereCoarseTiles = 8;        // a coarse cell: 8 x 8 tiles, 128 x 128 pixels
PR_CONST kSphereCoarseShift = 3;
PR_CONST kSphereBatchTestCells = 16;    // fine cells, tiles or coarse cells a batch's test reads at most
PR_CONST kSphereFineShift = 2;          // a fine cell: 4 x 4 pixels
PR_CONST kSphereFineSide = 4;
PR_CONST kSphereFinePerTile = 4;        // fine cells per tile side

// Particle index of a pixel (or impostor) without a sphere.
PR_CONST kNoParticle = 0xFFFFFFFFu;

// Primitive of the rasterization sphere pipelines' quad vertex shader (sphere_quads.vert.glsl).
PR_CONST kSphereQuadTriangles = 0; // 6 vertices per sphere, triangle list
PR_CONST kSphereQuadStrip = 1;     // one instance per sphere, a 4-vertex triangle strip

// Impostor of the rasterization sphere pipelines (specialization constant BILLBOARD of
// sphere_impostor.inc.glsl; SphereBillboard on the C++ side).
PR_CONST kSphereBillboardScreen = 0; // the tight screen-space box of the projected sphere
PR_CONST kSphereBillboardCamera = 1; // a camera-aligned square through the center, enlarged to cover it

// Shading of every sphere pipeline (sphere_shade.inc.glsl, and the CPU ray caster): a headlight (light
// at the eye), color * (ambient + diffuse * max(dot(normal, toEye), 0)); 0.25 + 0.75 = 1 where the
// surface faces the eye.
#define PR_SPHERE_AMBIENT 0.25
#define PR_SPHERE_DIFFUSE 0.75

// What every sphere pass reads about the frame: camera, targets and particle set constants. Lives in a
// small host-visible buffer (referenced by address from SpherePush), since it outgrows 128 B of push
// constants. Camera: view space is right-handed, looking down -z; the linear view depth is -z.
struct SphereFrame {
  mat4 view;            // world relative to the particles' origin -> view space
  vec4 pixelToRay;      // (sx, ox, sy, oy): the view ray through pixel position (x, y) (pixel centers at
                        // +0.5, row 0 at the top) is (x * sx + ox, y * sy + oy, -1); its t is view depth
  uint64_t framebuffer; // uint64_t per pixel: floatBits(view depth) << 32 | particle index; ones = empty
  uint64_t chunks;      // SphereChunks list of the large-sphere pass
  uint64_t parts;       // SpherePartRef[] of the particle set: particle i is in part i / partCapacity
  uint64_t image;       // uint[width * height] RGBA8, row 0 = top
  uint width;
  uint height;
  float nearW;          // spheres not entirely beyond this view depth (center depth - radius <= nearW) are
                        // culled, like points with c.w <= nearW
  float globalRadius;   // aos and xyz layouts
  uint globalColor;     // xyz layout (RGBA8)
  uint partCapacity;    // particles per part; every part but the last holds exactly this many
  uint chunkCapacity;   // entries the chunk list holds
  uint background;      // RGBA8 written where no sphere covers the pixel center
  uint64_t counters;    // uint[4] statistics of the frame: [0] spheres whose point size was clamped;
                        // sphere-compute counting its work: [0] pixels of large-sphere chunks drawn,
                        // [1] pixels tested (a visibility-word read each, before early-z; all passes),
                        // [2] depth atomics,
                        // [3] large-sphere chunks skipped by their tile's depth bound
  float maxPointSize;   // sphere-points: the device's largest point size
  uint tilesX;          // sphere-compute: tiles per row of tileBounds, ceil(width / kSphereTileSide)
  uint64_t tileBounds;  // sphere-compute: uint per screen tile, floatBits of a view depth that every pixel
                        // center of the tile is known to be covered at or nearer (ones: none known)
  uint64_t drawnChunks; // sphere-compute: uint[chunkCapacity], list indices of the chunks the large pass
                        // draws (those not behind their tiles' bounds); their count is SphereChunks::drawn
  // sphere-compute's occlusion culling of batches (kSphereBatchSize consecutive particles of a part):
  uint64_t batchBounds; // vec4 lo, vec4 hi per batch: bounds of its valid spheres, radii included (lo > hi:
                        // none valid); relative to the particles' origin, like the particles. Batch
                        // part * batchesPerPart + j holds particles [128 j, 128 j + 127] of the part
  uint64_t batchFlags;  // uint per batch: 1 = in the list the frame draws first (visible in the last frame)
  uint64_t batchList;   // SphereBatchList: the batches the second draw takes (found to show, not drawn first)
  uint64_t hiz;         // uint per screen tile (tilesX per row), then per coarse cell of
                        // kSphereCoarseTiles^2 tiles (coarseX per row), then per fine cell of
                        // kSphereFineSide^2 pixels: floatBits of a view depth that every pixel center of
                        // the tile or cell is covered at or nearer by the end of the frame (ones: none
                        // known)
  uint batches;         // batches of the set: batchesPerPart in every part but the last
  uint batchesPerPart;  // ceil(partCapacity / kSphereBatchSize)
  uint coarseX;         // coarse cells per row of hiz
  uint coarseOffset;    // index of hiz's first coarse cell (the tile count)
  uint fineOffset;      // index of hiz's first fine cell (4 x 4 pixels, 4 tilesX per row), after the coarse
  uint reserved[3];
};

// One part of a particle set on the GPU, as the resolve and large-sphere passes find it by index.
struct SpherePartRef {
  uint64_t address; // the part's buffer (layout above)
  uint count;
  uint reserved;
};

// Push constants of every sphere compute pass.
struct SpherePush {
  uint64_t frame;     // SphereFrame
  uint64_t particles; // the part drawn by this dispatch (per-sphere pass); with occlusion culling the
                      // SphereBatchList the per-sphere pass draws, or the batch cull fills for the next frame
  uint first;         // global index of the part's first particle
  uint count;         // particles in the part
  uint groupsX;       // workgroups per row of a 2D dispatch; the large-sphere pass: workgroups in all
  uint firstGroup;    // mesh pipelines: index of the draw's first workgroup (a part may need several draws)
};

// Mesh-shader sphere pipelines (VK_EXT_mesh_shader, shaders/sphere_mesh.inc.glsl): one invocation per
// sphere, meshlets of 31 or 15 spheres as in the 2023 study (the output arithmetic is in
// sphere_mesh.inc.glsl). With --task-cull a task workgroup of 32 invocations culls 4 x 32 = 128 spheres
// and launches mesh workgroups only for the survivors, passed as offsets in the task payload.
PR_CONST kSphereMeshletLarge = 31;
PR_CONST kSphereMeshletSmall = 15;
PR_CONST kSphereTaskGroupSize = 32;
PR_CONST kSphereTaskSpheres = 128;

// Push constants of sphere-rt's AABB pass (sphere_rt_aabbs.comp.glsl): one VkAabbPositionsKHR (6 floats,
// 24 bytes) per particle of a part, the input of the part's bottom-level acceleration structure.
struct SphereAabbPush {
  uint64_t frame;     // SphereFrame (the global radius of the aos and xyz layouts)
  uint64_t particles; // the part
  uint64_t aabbs;     // float[6 * count]: min xyz, max xyz, relative to the particles' origin
  uint count;         // particles in the part
  uint groupsX;       // workgroups per row of the 2D dispatch
};

// sphere-rt splits a part into pieces of SphereRtPush::pieceParticles particles, one bottom-level structure
// and one instance each, when one structure for the whole part would need a build scratch buffer larger than
// the device's largest buffer (4.51 GiB for 64 M spheres on an H200, whose largest buffer is 4 GiB). An
// instance's 24-bit custom index is part << kSphereRtPieceBits | piece: 64 pieces of a part (at 64 M
// particles a part, pieces of 1 M at the least), 262,144 parts.
PR_CONST kSphereRtPieceBits = 6;

// Push constants of the sphere-rt ray tracing pipeline (shaders/sphere_rt.*.glsl).
struct SphereRtPush {
  uint64_t frame;      // SphereFrame
  uint64_t tlas;       // device address of the top-level acceleration structure
  uint pieceParticles; // particles per piece of a part (kSphereRtPieceBits); the last piece may have fewer
  uint pad;
};

// Push constants of the viewer's present pass (shaders/view_present.*.glsl): one full-screen triangle
// whose fragments copy the renderer's RGBA8 image into the swapchain image, pixel for pixel where the
// sizes agree (nearest pixel otherwise, for the frames between a resize and the next render).
struct PresentPush {
  uint64_t image;     // uint[imageWidth * imageHeight], RGBA8, row 0 = top
  uint imageWidth;
  uint imageHeight;
  uint targetWidth;   // the swapchain image's size
  uint targetHeight;
};

// Push constants of the viewer's panel (Dear ImGui draw lists, shaders/view_panel.*.glsl): one draw per
// ImDrawCmd, vertices pulled from the list's buffers by device address.
struct PanelPush {
  uint64_t vertices;  // ImDrawVert[]: vec2 position, vec2 uv, RGBA8 color (20 B)
  uint64_t indices;   // 16-bit indices, two to a uint
  uint64_t font;      // the font atlas, one byte of coverage a texel, four texels to a uint
  uint firstIndex;    // of this draw in `indices`
  uint vertexOffset;  // added to every index
  uint fontWidth;
  uint fontHeight;
  float scaleX, scaleY; // pixels -> normalized device coordinates
  uint image;           // 1: `font` is an RGBA8 image of fontWidth x fontHeight (one uint a texel)
  uint unused;          // keeps the size a multiple of 8 in C++ and GLSL alike
};

PR_NAMESPACE_END

#endif
