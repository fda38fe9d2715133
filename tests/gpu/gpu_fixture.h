// A Vulkan context with the validation layer on for every GPU test; a validation error fails the test.
#pragma once

#include <cstdlib>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "gpu/context.h"

namespace pointrast::test {

class GpuTest : public ::testing::Test {
protected:
  void SetUp() override {
    gpu::ContextOptions options;
    // On unless POINTRAST_VALIDATION=0 (a machine without the layer installed).
    const char* env = std::getenv("POINTRAST_VALIDATION");
    options.validation = !(env && std::string(env) == "0");
    options.announce = false;
    context = std::make_unique<gpu::Context>(options);
  }
  void TearDown() override {
    EXPECT_EQ(context->validationErrors(), 0u) << "the validation layer reported errors (see stderr)";
    context.reset();
  }
  std::unique_ptr<gpu::Context> context;
};

} // namespace pointrast::test
