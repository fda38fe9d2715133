#include "gpu/spirv_reflect.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <unordered_map>

namespace pointrast::gpu {

namespace {

// Opcodes and enumerants from the SPIR-V 1.6 specification, section 3.
enum : uint32_t {
  OpEntryPoint = 15,
  OpExecutionMode = 16,
  OpExecutionModeId = 331,
  OpTypeInt = 21,
  OpTypeFloat = 22,
  OpTypeVector = 23,
  OpTypeMatrix = 24,
  OpTypeArray = 28,
  OpTypeStruct = 30,
  OpTypePointer = 32,
  OpConstant = 43,
  OpVariable = 59,
  OpDecorate = 71,
  OpMemberDecorate = 72,
  ExecutionModeLocalSize = 17,
  ExecutionModeLocalSizeId = 38,
  ExecutionModeOutputVertices = 26,
  ExecutionModeOutputPoints = 27,
  ExecutionModeOutputLinesEXT = 5269,
  ExecutionModeOutputPrimitivesEXT = 5270,
  ExecutionModeOutputTrianglesEXT = 5298,
  DecorationSpecId = 1,
  DecorationArrayStride = 6,
  DecorationMatrixStride = 7,
  DecorationBuiltIn = 11,
  DecorationOffset = 35,
  BuiltInPointSize = 1,
  StorageClassPushConstant = 9,
};

struct Type {
  uint32_t opcode = 0;
  std::vector<uint32_t> operands; // words after the result id
};

} // namespace

SpirvReflection reflectSpirv(std::span<const uint32_t> words) {
  assert(words.size() >= 5 && words[0] == 0x07230203u);
  std::unordered_map<uint32_t, Type> types;
  std::unordered_map<uint32_t, uint32_t> constants;
  std::unordered_map<uint32_t, uint32_t> arrayStride;
  std::unordered_map<uint64_t, uint32_t> memberOffset; // (struct << 32 | member) -> offset
  std::unordered_map<uint64_t, uint32_t> memberMatrixStride;
  uint32_t pushVariableType = 0;
  uint32_t localSizeIds[3] = {0, 0, 0};
  SpirvReflection result;

  for (size_t at = 5; at < words.size();) {
    uint32_t opcode = words[at] & 0xFFFFu;
    uint32_t count = words[at] >> 16;
    assert(count > 0 && at + count <= words.size());
    const uint32_t* op = &words[at];
    switch (opcode) {
    case OpEntryPoint:
      if (result.executionModel == ~0u) {
        result.executionModel = op[1];
        // The name: a nul-terminated string packed into the words after the function id, first character
        // in the lowest byte, which is the first byte in memory on the little-endian hosts pointrast runs on.
        const char* name = reinterpret_cast<const char*>(op + 3);
        result.entryPoint.assign(name, strnlen(name, size_t(count - 3) * 4));
      }
      break;
    case OpExecutionMode:
      if (op[2] == ExecutionModeLocalSize) std::copy(op + 3, op + 6, result.localSize);
      if (op[2] == ExecutionModeOutputVertices) result.outputVertices = op[3];
      if (op[2] == ExecutionModeOutputPrimitivesEXT) result.outputPrimitives = op[3];
      if (op[2] == ExecutionModeOutputPoints || op[2] == ExecutionModeOutputLinesEXT ||
          op[2] == ExecutionModeOutputTrianglesEXT)
        result.outputTopology = op[2];
      break;
    case OpExecutionModeId: // local_size_x = aConstant: sizes are ids of constants defined later
      if (op[2] == ExecutionModeLocalSizeId) std::copy(op + 3, op + 6, localSizeIds);
      break;
    case OpTypeInt:
    case OpTypeFloat:
    case OpTypeVector:
    case OpTypeMatrix:
    case OpTypeArray:
    case OpTypeStruct:
    case OpTypePointer:
      types[op[1]] = Type{opcode, std::vector<uint32_t>(op + 2, op + count)};
      break;
    case OpConstant:
      constants[op[2]] = op[3];
      break;
    case OpVariable:
      if (op[3] == StorageClassPushConstant) pushVariableType = op[1];
      break;
    case OpDecorate:
      if (op[2] == DecorationSpecId) result.specIds.push_back(op[3]);
      if (op[2] == DecorationArrayStride) arrayStride[op[1]] = op[3];
      if (op[2] == DecorationBuiltIn && op[3] == BuiltInPointSize) result.usesPointSize = true;
      break;
    case OpMemberDecorate:
      if (op[3] == DecorationOffset) memberOffset[(uint64_t(op[1]) << 32) | op[2]] = op[4];
      if (op[3] == DecorationMatrixStride) memberMatrixStride[(uint64_t(op[1]) << 32) | op[2]] = op[4];
      if (op[3] == DecorationBuiltIn && op[4] == BuiltInPointSize) result.usesPointSize = true;
      break;
    default:
      break;
    }
    at += count;
  }

  // Size in bytes of a type as laid out in an explicitly laid-out block: the end of its last byte.
  auto sizeOf = [&](auto&& self, uint32_t id, uint32_t matrixStride) -> uint32_t {
    const Type& t = types.at(id);
    switch (t.opcode) {
    case OpTypeInt:
    case OpTypeFloat:
      return t.operands[0] / 8;
    case OpTypeVector:
      return t.operands[1] * self(self, t.operands[0], 0);
    case OpTypeMatrix:
      return t.operands[1] * (matrixStride ? matrixStride : self(self, t.operands[0], 0));
    case OpTypeArray:
      return constants.at(t.operands[1]) * arrayStride.at(id);
    case OpTypePointer:
      return 8; // physical storage buffer pointer
    case OpTypeStruct: {
      uint32_t end = 0;
      for (uint32_t m = 0; m < t.operands.size(); ++m) {
        uint64_t key = (uint64_t(id) << 32) | m;
        uint32_t stride = memberMatrixStride.count(key) ? memberMatrixStride.at(key) : 0;
        end = std::max(end, memberOffset.at(key) + self(self, t.operands[m], stride));
      }
      return end;
    }
    default:
      assert(false && "unexpected type in push constants");
      return 0;
    }
  };
  for (int axis = 0; axis < 3; ++axis)
    if (localSizeIds[axis])
      result.localSize[axis] = constants.count(localSizeIds[axis]) ? constants.at(localSizeIds[axis]) : 0;
  if (pushVariableType) {
    const Type& pointer = types.at(pushVariableType);
    assert(pointer.opcode == OpTypePointer);
    result.pushConstantSize = sizeOf(sizeOf, pointer.operands[1], 0);
  }
  return result;
}

} // namespace pointrast::gpu
