// Every input a fuzz target ever failed on (tests/fuzz/regressions/TARGET/) replayed through the readers
// that target drives, so that the ordinary test builds (ASan and UBSan included) keep each fix. A new
// target's folder needs its line in kReaders.
#include <filesystem>
#include <functional>
#include <map>

#include "fuzz/prepare_steps.h"
#include "io/formats.h"
#include "io/io_test_util.h"
#include "io/particles/particles_io.h"

namespace {

namespace fs = std::filesystem;
using pointrast::InputError;
namespace io = pointrast::io;

const fs::path kRegressions = fs::path(POINTRAST_SOURCE_DIR) / "tests" / "fuzz" / "regressions";

// Each reader a target calls; every call must succeed or throw InputError.
const std::map<std::string, std::vector<std::function<void(const fs::path&)>>> kReaders = {
    {"las", {[](const fs::path& p) { io::readLas(p, iotest::quiet()); }, io::detail::probeLas}},
    {"ply",
     {[](const fs::path& p) { io::readPly(p, iotest::quiet()); }, io::detail::probePly,
      io::detail::statedCountPly}},
    {"xyz", {[](const fs::path& p) { io::readXyz(p, iotest::quiet()); }, io::detail::probeXyz}},
    {"mmpld",
     {[](const fs::path& p) {
        io::MmpldReadOptions options;
        options.progress = false;
        io::readMmpld(p, options);
        io::scanMmpld(p, options);
      },
      [](const fs::path& p) { io::probeMmpld(p); }}},
    {"prepare", {[](const fs::path& p) { fuzz::prepareLikeRender(io::readLas(p, iotest::quiet())); }}},
};

} // namespace

TEST(FuzzRegressions, EveryFoundInputIsReadOrRefused) {
  ASSERT_TRUE(fs::is_directory(kRegressions)) << kRegressions;
  size_t inputs = 0;
  for (const auto& folder : fs::directory_iterator(kRegressions)) {
    const std::string target = folder.path().filename().string();
    auto readers = kReaders.find(target);
    if (readers == kReaders.end()) {
      ADD_FAILURE() << "no readers listed for " << folder.path();
      continue;
    }
    for (const auto& input : fs::directory_iterator(folder.path())) {
      SCOPED_TRACE(input.path().string());
      ++inputs;
      for (const auto& read : readers->second) {
        try {
          read(input.path());
        } catch (const InputError&) {
        }
      }
    }
  }
  EXPECT_GT(inputs, 0u);
}
