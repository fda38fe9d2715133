// libFuzzer target for the MMPLD reader: readMmpld, probeMmpld and scanMmpld on arbitrary bytes, for the
// first frame and, in files of several, the last.
// Seeds: mmpld
#include "fuzz_input.h"
#include "io/particles/particles_io.h"

namespace {

void readFrame(const std::filesystem::path& path, uint32_t frame) {
  pointrast::io::MmpldReadOptions options;
  options.progress = false;
  options.frame = frame;
  try {
    pointrast::ParticleSet set = pointrast::io::readMmpld(path, options);
    if (set.xyz.size() != 3 * set.size() || (!set.radius.empty() && set.radius.size() != set.size()) ||
        (!set.colors.empty() && set.colors.size() != set.size()))
      __builtin_trap();
  } catch (const pointrast::InputError&) {
  }
  try {
    pointrast::io::probeMmpld(path, frame);
    pointrast::io::scanMmpld(path, options);
  } catch (const pointrast::InputError&) {
  }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pointrast::Progress::setEnabled(false);
  fuzz::MemFile file(data, size);
  readFrame(file.path(), 0);
  uint32_t frames = 0;
  try {
    frames = pointrast::io::probeMmpld(file.path()).frames;
  } catch (const pointrast::InputError&) {
  }
  if (frames > 1) readFrame(file.path(), frames - 1);
  return 0;
}
