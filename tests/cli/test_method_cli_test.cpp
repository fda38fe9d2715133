// The test-only point method of tests/methods (built with CMake POINTRAST_TEST_METHODS=ON): added as one
// table row and one shader, it must appear in every generated name list and render like atomicmin.
#include <string>

#include <gtest/gtest.h>

#include "cli_harness.h"

namespace pointrast::test {

#ifdef POINTRAST_TEST_METHOD_ROWS
constexpr bool kTestMethods = true;
#else
constexpr bool kTestMethods = false;
#endif

class TestMethodCli : public ::testing::Test {
protected:
  void SetUp() override {
    if (!kTestMethods) GTEST_SKIP() << "a product build: configure with -DPOINTRAST_TEST_METHODS=ON";
  }
};

TEST_F(TestMethodCli, HelpAndErrorsListTheRowAdded) {
  CliResult help = runPointrast("render --help");
  ASSERT_EQ(help.exitCode, 0) << help.err;
  EXPECT_NE(help.out.find("\n  closest-variant "), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("a closest-point variant from one table row and one shader"), std::string::npos);
  CliResult unknown = runPointrast("render terrain --points 1000 --method no-such-method -o " +
                                   (cliTempDir() / "unknown.png").string());
  EXPECT_EQ(unknown.exitCode, 1);
  EXPECT_NE(unknown.err.find("closest-variant"), std::string::npos) << unknown.err;
  CliResult bench = runPointrast("bench --methods no-such-method");
  EXPECT_EQ(bench.exitCode, 1);
  EXPECT_NE(bench.err.find("closest-variant"), std::string::npos) << bench.err;
}

// On the default device (lavapipe in CI, validation on): the variant's image is atomicmin's, byte for byte.
TEST_F(TestMethodCli, RendersTheSameImageAsAtomicMin) {
  const auto dir = cliTempDir();
  const std::string scene = "render terrain --points 50k --width 160 --height 100 --frames 1 -q ";
  CliResult variant = runPointrast(scene + "--method closest-variant -o " + (dir / "variant.png").string());
  ASSERT_EQ(variant.exitCode, 0) << variant.err;
  CliResult atomic = runPointrast(scene + "--method atomicmin -o " + (dir / "atomic.png").string());
  ASSERT_EQ(atomic.exitCode, 0) << atomic.err;
  const std::string image = slurp(dir / "variant.png");
  EXPECT_FALSE(image.empty());
  EXPECT_EQ(image, slurp(dir / "atomic.png"));
}

} // namespace pointrast::test
