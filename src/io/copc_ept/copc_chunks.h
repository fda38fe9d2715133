// The LAZ chunks of a COPC file as octree nodes: which chunk holds which node's cube, so a conversion
// that clips can leave whole chunks undecoded.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "cloud/cloud.h"

namespace pointrast::io {

struct CopcChunkCube {
  uint64_t offset = 0; // of the chunk in the file, as the LAZ chunk table gives it
  Bounds cube;         // the node's cube grown by two quantization steps (points rounded onto its faces)
};
// Every chunk whose node is known for certain. The hierarchy lists each node's chunk by offset; the
// chunk table lists the same chunks. Throws InputError for a damaged hierarchy (as openCopc does).
std::vector<CopcChunkCube> copcChunkCubes(const std::filesystem::path& path);

} // namespace pointrast::io
