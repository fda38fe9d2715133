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
  // The module's (first) entry point: its execution model (SpvExecutionModel: 0 vertex, 4 fragment,
  // 5 compute, 5364 task, 5365 mesh, 5313 ray generation, 5314 intersection, 5316 closest hit, 5317
  // miss) and name; pipelines pass "main".
  uint32_t executionModel = ~0u;
  std::string entryPoint;
  // Mesh shaders: the declared maxima (OutputVertices, OutputPrimitivesEXT) and the output primitive
  // (the execution mode: 27 OutputPoints, 5269 OutputLinesEXT, 5298 OutputTrianglesEXT), checked against
  // the device's limits before a pipeline is made.
  uint32_t outputVertices = 0;
  uint32_t outputPrimitives = 0;
  uint32_t outputTopology = 0;
};

// SpvExecutionModel values of the stages pointrast builds.
enum : uint32_t {
  kSpirvVertex = 0,
  kSpirvGeometry = 3,
  kSpirvFragment = 4,
  kSpirvCompute = 5,
  kSpirvRayGeneration = 5313,
  kSpirvIntersection = 5314,
  kSpirvClosestHit = 5316,
  kSpirvMiss = 5317,
  kSpirvTask = 5364,
  kSpirvMesh = 5365,
};
// Output primitives of a mesh shader (SpirvReflection::outputTopology).
enum : uint32_t {
  kSpirvOutputPoints = 27,
  kSpirvOutputTriangles = 5298,
};

// Asserts on a malformed module (embedded modules come from our own build).
SpirvReflection reflectSpirv(std::span<const uint32_t> words);

} // namespace pointrast::gpu
