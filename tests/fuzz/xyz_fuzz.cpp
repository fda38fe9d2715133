// libFuzzer target for the Xyz reader: readXyz and its probe on arbitrary bytes.
// Seeds: xyz
#include "fuzz_input.h"
#include "io/formats.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::run(
      data, size, [](const auto& path, const auto& options) { return pointrast::io::readXyz(path, options); },
      [](const auto& path) { pointrast::io::detail::probeXyz(path); });
}
