// Reading a contiguous run of a LAS file's point records, for a process that draws only its share of a
// file (docs/mpi.md): only the bytes of those records are read.
#pragma once

#include <cstdint>
#include <filesystem>

#include "io/reader.h"

namespace pointrast::io {

// Records [firstRecord, firstRecord + recordCount) of a LAS file (clamped to the header's count), as
// readLas() reads the whole file: bounds are those of the records read. Colors are 16-bit when a channel of these
// records is above 255; *colorMax (when given) receives the largest channel value, so that processes that
// read a file in shares can agree on the file's choice: a file is 16-bit when any share's largest value is
// above 255, and then a share whose values are all <= 255 has black colors (as readLas() gives them).
// Throws InputError as readLas() does.
PointCloud readLasRecords(const std::filesystem::path& path, const ReadOptions& options, uint64_t firstRecord,
                          uint64_t recordCount, uint16_t* colorMax);

} // namespace pointrast::io
