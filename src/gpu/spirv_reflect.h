// The few facts pointrast needs from a SPIR-V module, read from the module itself so pipeline layouts
// and dispatch sizes are never written by hand: the push-constant block size, the workgroup size and
// the specialization constant ids.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pointrast::gpu {

struct SpirvReflection {
  uint32_t pushConstantSize = 0;     // bytes of the push-constant block (0 if none)
  uint32_t localSize[3] = {1, 1, 1}; // from LocalSize; 0 if given by specialization constants
  std::vector<uint32_t> specIds;     // SpecId decorations present
  bool usesPointSize = false;        // writes gl_PointSize (vertex stage)
};

// Asserts on a malformed module (embedded modules come from our own build).
SpirvReflection reflectSpirv(std::span<const uint32_t> words);

} // namespace pointrast::gpu
