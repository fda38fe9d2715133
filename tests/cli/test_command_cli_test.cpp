// The test-only command of tests/commands (built with CMake POINTRAST_TEST_COMMANDS=ON): added as its
// cmd_*.cpp and one row, it must be listed by `pointrast --help`, run, and refuse bad input like the others.
#include <string>

#include <gtest/gtest.h>

#include "cli_harness.h"

namespace pointrast::test {

#ifdef POINTRAST_TEST_COMMAND_ROWS
constexpr bool kTestCommands = true;
#else
constexpr bool kTestCommands = false;
#endif

class TestCommandCli : public ::testing::Test {
protected:
  void SetUp() override {
    if (!kTestCommands) GTEST_SKIP() << "a product build: configure with -DPOINTRAST_TEST_COMMANDS=ON";
  }
};

TEST_F(TestCommandCli, HelpListsTheCommandAfterTheProductOnes) {
  CliResult r = runPointrast("--help");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const size_t serve = r.out.find("serve"), echo = r.out.find("test-echo");
  ASSERT_NE(echo, std::string::npos) << r.out;
  EXPECT_LT(serve, echo) << r.out;
  r = runPointrast("test-echo --help");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("--text"), std::string::npos) << r.out;
}

TEST_F(TestCommandCli, RunsAndRefusesBadInputWithOneLine) {
  CliResult r = runPointrast("test-echo --text hello");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out, "hello\n");
  r = runPointrast("test-echo --text ''");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(r.err, "pointrast: --text must not be empty\n");
  r = runPointrast("test-echo");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("--text"), std::string::npos) << r.err;
}

} // namespace pointrast::test
