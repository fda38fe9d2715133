// Adaptive coordinate precision of the 2022 paper ("Software Rasterization of 2 Billion Points in Real
// Time", Schuetz, Kerbl, Wimmer, section 4.3): inside its batch, every coordinate is quantized to 30 bits
// relative to the batch bounds, and the bits are split over three 32-bit words per point so a frame loads
// only as many words as the batch's projected size needs:
//
//   word    bits 29..20 of x | bits 29..20 of y << 10 | bits 29..20 of z << 20    ("high",   4 B)
//   word    bits 19..10 of x | ...                                                ("medium", 4 B)
//   word    bits  9..0  of x | ...                                                ("low",    4 B)
//
// With k words a coordinate is known to 10k bits: the decoder takes the centre of the remaining cell, so
// the error is at most size / 2^(10k + 1) per axis (plus the 30-bit rounding, size / 2^31).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "cloud/batch.h"

namespace pointrast {

constexpr uint32_t kBatchWordBits = 10;                  // bits per axis in one word
constexpr uint32_t kBatchCoordinateBits = 30;            // 3 words x 10 bits
constexpr uint32_t kBatchCoordinateMax = (1u << 30) - 1; // largest quantized coordinate

// Encodes the batch's points into high/medium/low[0..batch.count). Preconditions: batch.bounds holds
// every point of the batch (as makeBatches gives it). An axis of zero extent encodes as 0.
void encodeBatchWords(uint32_t* high, uint32_t* medium, uint32_t* low, const PointCloud& cloud,
                      const Batch& batch);

// Decodes one point from its first `words` words (1..3) in double precision, world coordinates.
glm::dvec3 decodeBatchWords(const Batch& batch, uint32_t high, uint32_t medium, uint32_t low, int words);

// Largest per-axis decoding error with `words` words for a batch of this size: half a cell plus the
// 30-bit rounding.
glm::dvec3 batchWordsError(const Batch& batch, int words);

} // namespace pointrast
