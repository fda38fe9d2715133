// The structs and constants of the octree builder's GPU index phase (render/gpu_indexer.cpp and
// shaders/lod_index_*.comp.glsl), defined once for C++ and GLSL like shared.h, which it extends; C++
// checks their layout in render/gpu_indexer.cpp. A header of its own: the renderer's files do not
// depend on it.
#ifndef POINTRAST_LOD_INDEX_SHARED_H
#define POINTRAST_LOD_INDEX_SHARED_H

#include "shared.h"

PR_NAMESPACE_BEGIN

// Threads per workgroup of every index pass, and points per thread of a radix sort's tile: a workgroup
// sorts tiles of 256 x 16 = 4096 points.
PR_CONST kIndexGroupSize = 256;
PR_CONST kRadixItemsPerThread = 16;
PR_CONST kRadixTileItems = kIndexGroupSize * kRadixItemsPerThread;
// Bits of the code a radix pass sorts on (256 buckets).
PR_CONST kRadixBits = 8;
// A point no subsample has taken (yet): the taken level of the points that stay in leaves.
PR_CONST kNotTaken = 0xFFFFFFFFu;
// Bits of a Morton code per level, and the code's levels (cloud/lod_grid.h: kCodeLevels).
PR_CONST kIndexCodeLevels = 21;

// A point as the builder holds it while indexing (lod::LodItem: its Morton code, its 24-byte record and
// the ref of its tail), read by the passes straight from the builder's array.
struct IndexItem {
  uint64_t code;
  int x, y, z;
  uint rg;        // rgb[0] | rgb[1] << 16
  uint bIntensity; // rgb[2] | intensity << 16
  uint rest;       // returnNumber, classification, pointSourceId
  uint64_t ref;
};

// One pass of the radix sort (histogram, scan or scatter), on (code, index) pairs.
struct RadixPush {
  uint64_t keysIn;    // uint64_t[count]
  uint64_t keysOut;   // uint64_t[count]
  uint64_t valuesIn;  // uint[count]
  uint64_t valuesOut; // uint[count]
  uint64_t histogram; // uint[256 * tiles], bucket-major
  uint64_t items;     // IndexItem[count]: the first pass's keys and values come from here
  uint count;
  uint shift; // the pass sorts on bits shift .. shift + 7 of the code
  uint tiles;
  uint groupsX;
};

// One level's subsample over the sorted points (or the gather that makes their sorted copy). The cells'
// sums live in `cells`, arrays of count entries one after the other: the nearest untaken point's distance
// (uint64_t), the sums of its untaken points' red, green and blue (3 x uint64_t), their number (uint), the
// first untaken point at the nearest distance (uint), and each point's cell's first point (uint). A
// cell's entries sit at its first point's place; every entry starts empty (the gather sets them) and a
// cell's first point empties them again after its level. After the arrays, one uint: not 0 when two
// sorted points share a code (set by the gather).
struct IndexLevelPush {
  uint64_t items;  // IndexItem[count], in the order the builder gave them
  uint64_t order;  // uint[count]: the sorted points' places in items
  uint64_t sorted; // IndexItem[count], sorted (made by the gather)
  uint64_t taken;  // uint[count]: the level whose subsample took each sorted point, or kNotTaken
  uint64_t colors; // uvec2[count]: a taken point's color (averaged where colors are filtered)
  uint64_t leafPoints; // a node whose cube holds more points is split
  int64_t edgeQuanta;  // the cube's edge in quanta (the grid is isotropic)
  int qmin[3];         // the cube's corner in quanta
  uint count;
  uint level;      // the level being subsampled
  uint cellLevel;  // the level of its grid's cells
  uint chunkLevel; // nodes above the chunk's are inner whatever their count here
  uint averageColors;
  uint groupsX;
  uint pad;
  uint64_t cells; // the cells' sums (above): 44 bytes a point, and the flag
  uint64_t keys;  // uint64_t[count]: the sorted codes (the radix sort's last keys), read by the gather
};

PR_NAMESPACE_END

#endif
