// libFuzzer target for the LAS reader: readLas and its probe on arbitrary bytes, then the same file as the
// octree builder streams it (a PointSource cut into small pieces, each read on its own).
// Seeds: las
#include <vector>

#include "fuzz_input.h"
#include "io/formats.h"
#include "io/las/las_source.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::run(
      data, size, [](const auto& path, const auto& options) { return pointrast::io::readLas(path, options); },
      [](const auto& path) { pointrast::io::detail::probeLas(path); });
  // Pieces of 7 records: a 64 KiB input holds a few hundred, so their boundaries meet the file's end.
  pointrast::io::detail::setPieceRecords(7);
  fuzz::MemFile file(data, size);
  try {
    auto source = pointrast::io::detail::openLasSource(file.path());
    std::vector<pointrast::PointRecord> records;
    for (size_t i = 0; i < source->pieces().size(); ++i) {
      source->readPiece(i, records);
      if (records.size() != source->pieces()[i].count) __builtin_trap();
    }
  } catch (const pointrast::InputError&) {
  }
  return 0;
}
