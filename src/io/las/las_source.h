// LAS point records as PointRecords: the streaming source behind openPointSource() for LAS files, and the
// record decoding that other LAS-shaped sources (LAZ chunks decoded into LAS records) share.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>

#include "cloud/point_record.h"
#include "io/point_source.h"

namespace pointrast::io::detail {

// Records per piece of a LAS source: ~1 M, so a 1 G-point file is a thousand pieces for the cores to
// share, and one piece (34 MB of PF3 records) is read with one positional read per megabyte.
inline constexpr uint64_t kLasPieceRecords = uint64_t(1) << 20;

// Records per piece of sources opened from now on (default kLasPieceRecords). Tests lower it to cut
// small files into many pieces; 0 restores the default.
void setPieceRecords(uint64_t records);
uint64_t pieceRecords();

// Decodes `count` LAS point records of point format `pointFormat` (0-10), `stride` bytes apart, into out:
// the integers and 16-bit color values as stored, intensity, return number (3 bits for formats 0-5,
// 4 bits for 6-10), classification (the low 5 bits of byte 15 for formats 0-5, byte 16 for 6-10, as
// readLas keeps it) and point source id (byte 18, or 20 for 6-10). The caller has checked that
// stride is at least the format's record size.
void decodeLasRecords(const uint8_t* src, uint64_t stride, uint64_t count, int pointFormat, PointRecord* out);

// Opens a LAS file (not LAZ) as a PointSource. Throws InputError for a damaged header, naming the file.
std::unique_ptr<PointSource> openLasSource(const std::filesystem::path& path);

} // namespace pointrast::io::detail
