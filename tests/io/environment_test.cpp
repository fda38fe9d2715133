// Test-binary setup: no progress lines in test output, and (under AddressSanitizer) any single
// allocation above 1 GiB aborts the run, so a reader that trusts a lying header cannot pass by luck.
#include <gtest/gtest.h>

#include "base/progress.h"

extern "C" const char* __asan_default_options() {
  return "max_allocation_size_mb=1024";
}

namespace {

class QuietEnvironment : public ::testing::Environment {
public:
  void SetUp() override { pointrast::Progress::setEnabled(false); }
};

const auto* const kQuiet = ::testing::AddGlobalTestEnvironment(new QuietEnvironment);

} // namespace
