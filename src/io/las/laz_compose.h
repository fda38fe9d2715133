// LAZ files composed from the chunks of an existing one. Chunks decode on their own, so any sequence of
// a file's chunks, with the same header and LASzip VLR and a rebuilt chunk table, is a valid LAZ file:
// the benchmark replicates a small real file to millions of points this way, and tests cut real files
// down to a few chunks (or damage the table on purpose).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "io/las/laz_format.h"

namespace pointrast::io {

// The bytes of a LAZ file holding the chunks `picks` of `source` (indices into its chunk table, in that
// order, repeats allowed). The header, VLRs and LASzip VLR are the source's, with the point counts
// updated, the points-by-return counts zeroed (unknown without decoding), variable-size chunks, and
// COPC's VLRs and all EVLRs dropped (their offsets would no longer hold). Throws InputError.
std::vector<uint8_t> composeLaz(const std::filesystem::path& source, const std::vector<size_t>& picks);

// The same written to a file (under a temporary name, renamed when complete).
void writeComposedLaz(const std::filesystem::path& source, const std::vector<size_t>& picks,
                      const std::filesystem::path& out);

} // namespace pointrast::io
