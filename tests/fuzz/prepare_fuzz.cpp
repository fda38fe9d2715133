// libFuzzer target for the preparation a render applies to a file's cloud (prepare_steps.h), on whatever
// a LAS file can state. LAS is the way in because its header sets scale and offset freely: subnormal
// scales and coordinates near the limits of double reach code that the readers' own targets never run.
// Seeds: las
#include "fuzz_input.h"
#include "io/formats.h"
#include "prepare_steps.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pointrast::Progress::setEnabled(false);
  fuzz::MemFile file(data, size);
  pointrast::io::ReadOptions options;
  options.progress = false;
  try {
    fuzz::prepareLikeRender(pointrast::io::readLas(file.path(), options));
  } catch (const pointrast::InputError&) {
  }
  return 0;
}
