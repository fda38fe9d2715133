// libFuzzer target for the Ply reader: readPly, its probe and its header count on arbitrary bytes.
// Seeds: ply
#include "fuzz_input.h"
#include "io/formats.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::run(
      data, size, [](const auto& path, const auto& options) { return pointrast::io::readPly(path, options); },
      [](const auto& path) {
        try {
          pointrast::io::detail::statedCountPly(path);
        } catch (const pointrast::InputError&) {
        }
        pointrast::io::detail::probePly(path);
      });
}
