// libFuzzer target for the MMPLD reader: readMmpld, probeMmpld and scanMmpld on arbitrary bytes.
// Seeds: mmpld
#include "fuzz_input.h"
#include "io/particles_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pointrast::Progress::setEnabled(false);
  fuzz::MemFile file(data, size);
  pointrast::io::MmpldReadOptions options;
  options.progress = false;
  try {
    pointrast::ParticleSet set = pointrast::io::readMmpld(file.path(), options);
    if (set.xyz.size() != 3 * set.size() || (!set.radius.empty() && set.radius.size() != set.size()) ||
        (!set.colors.empty() && set.colors.size() != set.size()))
      __builtin_trap();
  } catch (const pointrast::InputError&) {
  }
  try {
    pointrast::io::probeMmpld(file.path());
    pointrast::io::scanMmpld(file.path(), options);
  } catch (const pointrast::InputError&) {
  }
  return 0;
}
