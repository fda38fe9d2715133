// The rasterization of sphere-compute (passes 1 and 2): the large-sphere chunk list and the
// visibility-buffer write.
#include "sphere_particles.inc.glsl"

// The large-sphere list: chunks asked for (64 bits: it keeps counting past the capacity and must never
// wrap), spheres that drew some of their chunks themselves because the list was full, then entries
// (global particle index, box x0 | y0 << 16, box width | height << 16, first pixel of the chunk in the
// box's row-major order).
layout(buffer_reference, std430, buffer_reference_align = 16) buffer SphereChunks {
  uint64_t count;
  uint spilled;
  uint reserved;
  uvec4 entries[];
};

// Ray test at pixel p (inside the image) and the visibility-buffer write: the 64-bit word
// floatBits(view depth) << 32 | particle index, minimum wins (depth > 0 orders like an unsigned integer;
// equal depths go to the lower index, whatever the order of arrival). Early-z, with plain reads: a pixel
// already holding something nearer than the sphere's front (center depth - radius) skips the ray test,
// and the atomic runs only if the word can still win.
void coverPixel(vec3 center, float radius, uint index, ivec2 p) {
  uint pixel = uint(p.y) * frame.width + uint(p.x);
  Uint64Array fb = Uint64Array(frame.framebuffer);
  if (uint(fb.v[pixel] >> 32) < floatBitsToUint(-center.z - radius)) return;
  float depth;
  if (!intersectSphere(center, radius, sphereRay(frame.pixelToRay, vec2(p) + 0.5), depth)) return;
  uint64_t word = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(index);
  if (word < fb.v[pixel]) atomicMin(fb.v[pixel], word);
}

// Every pixel of box (x0, y0, x1, y1) by the calling invocation alone.
void coverBox(vec3 center, float radius, uint index, ivec4 box) {
  for (int y = box.y; y <= box.w; ++y)
    for (int x = box.x; x <= box.z; ++x)
      coverPixel(center, radius, index, ivec2(x, y));
}

// Pixels [first, first + kSphereChunkPixels) of the box's row-major order by the calling invocation.
void coverChunk(vec3 center, float radius, uint index, ivec4 box, uint first) {
  uint width = uint(box.z - box.x + 1), pixels = width * uint(box.w - box.y + 1);
  for (uint pixel = first; pixel < min(first + kSphereChunkPixels, pixels); ++pixel)
    coverPixel(center, radius, index, box.xy + ivec2(pixel % width, pixel / width));
}
