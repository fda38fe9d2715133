// The rasterization of sphere-compute (passes 1 to 3): the large-sphere chunk list, the tile depth bounds
// and the visibility-buffer write.
#include "sphere_particles.inc.glsl"

// COUNT_WORK: count pixels tested, depth atomics and skipped chunks in frame.counters (one global atomic
// each: for tests and measurements of the work, never for timing). TILE_BOUND: skip large-sphere chunks
// behind their tile's depth bound (off only to compare the work with and without it). TILE_CUT_PIXELS:
// the box size (pixels) above which a large sphere is cut along screen tiles rather than into bands of
// whole box rows (kSphereTileCutPixels; other values only to count the work of other choices).
layout(constant_id = 3) const uint COUNT_WORK = 0;
layout(constant_id = 4) const uint TILE_BOUND = 1;
layout(constant_id = 5) const uint TILE_CUT_PIXELS = kSphereTileCutPixels;

// The large-sphere list: chunks asked for (64 bits: it keeps counting past the capacity and must never
// wrap), spheres that drew some of their chunks themselves because the list was full, chunks left to draw
// after the cull pass (their list indices in SphereFrame::drawnChunks), then entries
// (global particle index, chunk x0 | y0 << 16, chunk x1 | y1 << 16 (inclusive pixel bounds of at most
// kSphereChunkPixels pixels: a screen tile or a band of whole box rows, clipped to the sphere's box),
// floatBits of the sphere's front depth: center depth - radius).
layout(buffer_reference, std430, buffer_reference_align = 16) buffer SphereChunks {
  uint64_t count;
  uint spilled;
  uint drawn;
  uvec4 entries[];
};

// A list of batches for the per-sphere pass of an occlusion-culled frame (the batches visible in the
// last frame, drawn first; those found to show after that, drawn second): their count, then indices.
layout(buffer_reference, std430, buffer_reference_align = 16) buffer SphereBatchList {
  uint count;
  uint reserved[3];
  uint entries[];
};

void countWork(uint counter) {
  if (COUNT_WORK != 0) atomicAdd(UintArray(frame.counters).v[counter], 1u);
}

// Ray test at pixel p (inside the image) and the visibility-buffer write: the 64-bit word
// floatBits(view depth) << 32 | particle index, minimum wins (depth > 0 orders like an unsigned integer;
// equal depths go to the lower index, whatever the order of arrival). Early-z, with plain reads: a pixel
// already holding something nearer than the sphere's front (center depth - radius) skips the ray test,
// and the atomic runs only if the word can still win.
void coverPixel(vec3 center, float radius, uint index, ivec2 p) {
  countWork(1);
  uint pixel = uint(p.y) * frame.width + uint(p.x);
  Uint64Array fb = Uint64Array(frame.framebuffer);
  if (uint(fb.v[pixel] >> 32) < floatBitsToUint(-center.z - radius)) return;
  float depth;
  if (!intersectSphere(center, radius, sphereRay(frame.pixelToRay, vec2(p) + 0.5), depth)) return;
  uint64_t word = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(index);
  if (word < fb.v[pixel]) {
    countWork(2);
    atomicMin(fb.v[pixel], word);
  }
}

// Every pixel of box (x0, y0, x1, y1) by the calling invocation alone.
void coverBox(vec3 center, float radius, uint index, ivec4 box) {
  for (int y = box.y; y <= box.w; ++y)
    for (int x = box.x; x <= box.z; ++x)
      coverPixel(center, radius, index, ivec2(x, y));
}

// Inclusive pixel bounds (x0, y0, x1, y1) <-> the two words of a chunk entry.
uvec2 packChunk(ivec4 r) {
  return uvec2(uint(r.x) | (uint(r.y) << 16), uint(r.z) | (uint(r.w) << 16));
}
ivec4 unpackChunk(uvec2 w) {
  return ivec4(w.x & 0xFFFFu, w.x >> 16, w.y & 0xFFFFu, w.y >> 16);
}

// Screen tile t's pixels, clipped to the image.
ivec4 tilePixels(uvec2 t) {
  ivec2 lo = ivec2(t << kSphereTileShift);
  return ivec4(lo, min(lo + int(kSphereTileSide) - 1, ivec2(frame.width, frame.height) - 1));
}

uint tileOf(ivec2 pixel) {
  return uint(pixel.y >> kSphereTileShift) * frame.tilesX + uint(pixel.x >> kSphereTileShift);
}

// Whether a listed chunk lies behind the depth bound of every tile it touches, so that its sphere loses
// each of its pixels: a tile chunk touches one tile, a band of box rows up to a few; a chunk touching
// more than 2 x 2 tiles is never skipped. The four reads are unrolled: llvmpipe ends an invocation's
// loops after 65535 iterations in all, and a loop here would count against the caller's.
bool chunkHidden(uvec4 entry) {
  if (TILE_BOUND == 0) return false;
  ivec4 tiles = ivec4(unpackChunk(entry.yz)) >> int(kSphereTileShift);
  if (any(greaterThan(tiles.zw - tiles.xy, ivec2(1)))) return false;
  UintArray bounds = UintArray(frame.tileBounds);
  uint row0 = uint(tiles.y) * frame.tilesX, row1 = uint(tiles.w) * frame.tilesX;
  uint bound = max(max(bounds.v[row0 + uint(tiles.x)], bounds.v[row0 + uint(tiles.z)]),
                   max(bounds.v[row1 + uint(tiles.x)], bounds.v[row1 + uint(tiles.z)]));
  return entry.w > bound;
}
