// Every point of a level-of-detail octree as one PointCloud, for what draws or exports a whole cloud (the
// brute-force renderers, `convert` with a vertex order). Works on any NodeSource: the hierarchy is read in
// full, then nodes are decoded on all cores, each on its own, into their place in the cloud; points keep
// the depth-first node order of forEachNode.
#pragma once

#include "cloud/cloud.h"
#include "cloud/octree.h"

namespace pointrast::lod {

struct OctreeCloudOptions {
  bool progress = true;       // progress line on stderr when it is a terminal
  bool keepAttributes = true; // intensity, classification, return number
};

// Colors follow the LAS reader's rule: any channel above 255 means 16-bit colors (shifted down by 8),
// decided over all points; the source's colorMax is only the first guess. Throws InputError from the
// source, or when a node holds more points than the hierarchy listed.
PointCloud readOctreeCloud(NodeSource& source, const OctreeCloudOptions& options = {});

} // namespace pointrast::lod
