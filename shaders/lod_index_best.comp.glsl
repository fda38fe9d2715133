#version 460
// One level's subsample, pass 2 of 3: of a cell's untaken points at its nearest distance, the first in
// sorted order (the CPU's tie rule) becomes the cell's choice. A workgroup in one cell takes the least
// of its candidates first and makes one atomic update.
#include "lod_index.inc.glsl"

layout(local_size_x = kIndexGroupSize) in;
layout(push_constant) uniform Push { IndexLevelPush pc; };

shared uint candidates[kIndexGroupSize];
shared uint firstHere[kIndexGroupSize];

void main() {
  const uint base = groupBase(pc.groupsX), t = gl_LocalInvocationIndex, i = base + t;
  if (base >= pc.count) return; // the whole workgroup: no barrier is skipped by part of it
  const bool valid = i < pc.count;
  uint first = 0, candidate = kNotTaken;
  if (valid) {
    first = cellFirst(pc).v[i];
    if (UintArray(pc.taken).v[i] == kNotTaken) {
      const uint64_t distance = distanceTo(IndexItems(pc.sorted).v[i], cellCenter2(pc, cellOf(pc, i)));
      if (distance == cellNearest(pc).v[first]) candidate = i;
    }
  }
  const uint last = min(pc.count - base, kIndexGroupSize) - 1;
  firstHere[t] = first;
  candidates[t] = candidate;
  barrier();
  if (firstHere[0] == firstHere[last]) {
    for (uint stride = kIndexGroupSize / 2; stride > 0; stride /= 2) {
      if (t < stride) candidates[t] = min(candidates[t], candidates[t + stride]);
      barrier();
    }
    if (t == 0 && candidates[0] != kNotTaken) atomicMin(cellBest(pc).v[first], candidates[0]);
  } else if (candidate != kNotTaken) {
    atomicMin(cellBest(pc).v[first], candidate);
  }
}
