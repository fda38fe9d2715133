// BatchStats from the statistics rows the batch kernels and the LOD node kernels add to: one reading of the
// counters for both, so that `batch` and `lod` report the 2022 paper's Table 2 the same way.
#pragma once

#include <cstdint>

#include "gpu/shared_types.h"
#include "render/renderer.h"

namespace pointrast {

// `rows`: shared::kBatchStatSlots rows of shared::kBatchStatCount counters (spread so that workgroups contend
// less); `hqs`: the words are read twice and each blended point's color once more.
BatchStats batchStatsFromRows(const uint64_t (&rows)[shared::kBatchStatSlots][shared::kBatchStatCount],
                              bool hqs);

} // namespace pointrast
