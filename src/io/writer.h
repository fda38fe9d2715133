// Writers. Each writes to "<path>.partial" and renames over path only when everything was written, so a
// failure (disk full, bad input) never leaves a half-written file under the requested name.
#pragma once

#include <cstdint>
#include <filesystem>

#include "cloud/cloud.h"

namespace pointrast::io {

enum class LasFlavor {
  Las12Pf2, // LAS 1.2, point format 2 (RGB, no GPS time): 26 B records
  Las12Pf3, // LAS 1.2, point format 3 (GPS time + RGB): 34 B records
  Las14Pf7, // LAS 1.4, point format 7 (64-bit counts): 36 B records
};

// Writes the cloud with its own scale/offset. Colors are written 16-bit (v * 257 = v << 8 | v). LAS 1.2
// can hold at most 2^32 - 1 points; more needs Las14Pf7 (InputError otherwise).
void writeLas(const std::filesystem::path& path, const PointCloud& cloud, LasFlavor flavor);

// Writes RGBA8 pixels (row 0 = top) as an 8-bit RGB PNG (alpha dropped).
void writePng(const std::filesystem::path& path, uint32_t width, uint32_t height, const uint32_t* rgba);

} // namespace pointrast::io
