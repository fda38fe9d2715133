// Includes and helpers shared by every shader. Buffer-reference types address the scene's buffers by
// device address (see RasterPush in shared.h).
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_atomic_int64 : require

#include "shared.h"

// The pixel index of a point that lands on no pixel (dropped by the near plane or outside the image).
const uint kNoPixel = 0xFFFFFFFFu;

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer FloatArray { float v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer UintArray { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer Uint64Array { uint64_t v[]; };
// 16-byte loads (point words, particle records, four points' positions or colors at once).
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Vec4Array { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Uvec4Array { uvec4 v[]; };
