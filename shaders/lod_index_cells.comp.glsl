#version 460
// One level's subsample, pass 1 of 3: each point finds its grid cell's first sorted point (the cell's
// place in the sums) and, if no level above took it, adds its distance to the cell's center (the
// minimum) and its color (the sums) to the cell. A workgroup whose points all lie in one cell (the coarse
// levels: cells of millions of points) adds them up first and makes one atomic update instead of 256.
#include "lod_index.inc.glsl"

layout(local_size_x = kIndexGroupSize) in;
layout(push_constant) uniform Push { IndexLevelPush pc; };

shared uint64_t cellsHere[kIndexGroupSize];
shared uint64_t nearestHere[kIndexGroupSize];
shared uint64_t sumsHere[3][kIndexGroupSize];
shared uint reachedHere[kIndexGroupSize];
shared uint firstHere[kIndexGroupSize];
shared uint firstOfFirstCell; // the workgroup's first cell's first point

void main() {
  const uint base = groupBase(pc.groupsX), t = gl_LocalInvocationIndex, i = base + t;
  if (base >= pc.count) return; // the whole workgroup: no barrier is skipped by part of it
  const bool valid = i < pc.count;
  // Past the end: a cell above every code, so that the sorted order holds in cellsHere.
  const uint64_t cell = valid ? cellOf(pc, i) : ~0ul;
  cellsHere[t] = cell;
  if (t == 0) {
    // Where the workgroup's first cell started before it: a binary search over the sorted points.
    firstOfFirstCell = base;
    if (base > 0 && cellOf(pc, base - 1) == cell)
      firstOfFirstCell = firstAtLeast(IndexItems(pc.sorted), 0, base - 1, cellShiftOf(pc), cell);
  }
  barrier();

  // The cell's first point: within the workgroup by a binary search over its cells, or the first cell's.
  uint lo = 0, hi = t;
  while (lo < hi) {
    const uint mid = (lo + hi) / 2;
    if (cellsHere[mid] < cell)
      lo = mid + 1;
    else
      hi = mid;
  }
  const uint first = lo == 0 ? firstOfFirstCell : base + lo;
  if (valid) cellFirst(pc).v[i] = first;

  // The point's share: its distance and color where no level above took it.
  bool untaken = false;
  uint64_t distance = ~0ul, rgb[3] = uint64_t[3](0ul, 0ul, 0ul);
  if (valid && UintArray(pc.taken).v[i] == kNotTaken) {
    untaken = true;
    const IndexItem p = IndexItems(pc.sorted).v[i];
    distance = distanceTo(p, cellCenter2(pc, cell));
    rgb = uint64_t[3](uint64_t(p.rg & 0xFFFFu), uint64_t(p.rg >> 16), uint64_t(p.bIntensity & 0xFFFFu));
  }

  const uint last = min(pc.count - base, kIndexGroupSize) - 1; // the workgroup's last valid point
  firstHere[t] = first;
  barrier();
  if (firstHere[0] == firstHere[last]) {
    // One cell: a tree reduction over the workgroup, then one update.
    nearestHere[t] = distance;
    for (int c = 0; c < 3; ++c)
      sumsHere[c][t] = rgb[c];
    reachedHere[t] = untaken ? 1u : 0u;
    barrier();
    for (uint stride = kIndexGroupSize / 2; stride > 0; stride /= 2) {
      if (t < stride) {
        nearestHere[t] = min(nearestHere[t], nearestHere[t + stride]);
        for (int c = 0; c < 3; ++c)
          sumsHere[c][t] += sumsHere[c][t + stride];
        reachedHere[t] += reachedHere[t + stride];
      }
      barrier();
    }
    if (t == 0 && reachedHere[0] > 0) {
      atomicMin(cellNearest(pc).v[first], nearestHere[0]);
      for (int c = 0; c < 3; ++c)
        atomicAdd(cellSums(pc).v[3 * first + c], sumsHere[c][0]);
      atomicAdd(cellReached(pc).v[first], reachedHere[0]);
    }
  } else if (untaken) {
    atomicMin(cellNearest(pc).v[first], distance);
    for (int c = 0; c < 3; ++c)
      atomicAdd(cellSums(pc).v[3 * first + c], rgb[c]);
    atomicAdd(cellReached(pc).v[first], 1u);
  }
}
