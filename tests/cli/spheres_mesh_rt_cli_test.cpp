// `pointrast render --method sphere-mesh-points|sphere-mesh-tris|sphere-rt` as a user runs it: a PNG (and
// the method's own JSON keys) where the device has the extension, otherwise exit 1 with one line naming
// the method and the missing extension, and no file; mesh options refused where they mean nothing.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "cli/cli_harness.h"

namespace pointrast::test {

namespace {

namespace fs = std::filesystem;

size_t lineCount(const std::string& text, const std::string& prefix) {
  size_t n = 0;
  for (size_t at = 0; at < text.size();) {
    size_t end = text.find('\n', at);
    if (text.compare(at, prefix.size(), prefix) == 0) ++n;
    if (end == std::string::npos) break;
    at = end + 1;
  }
  return n;
}

void expectCleanFailure(const std::string& args, const fs::path& output, const std::string& says) {
  fs::remove(output);
  CliResult r = runPointrast(args);
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_NE(r.err.find(says), std::string::npos) << args << ": stderr was " << r.err;
  EXPECT_EQ(lineCount(r.err, "pointrast: "), 1u) << r.err;
  EXPECT_FALSE(fs::exists(output)) << args << " left " << output;
}

} // namespace

TEST(SpheresMeshRtCli, RendersOrSaysWhyNot) {
  struct Case {
    const char* args;
    const char* method;
    const char* extension;
    const char* jsonKey;
  };
  for (Case c :
       {Case{"--method sphere-mesh-points", "sphere-mesh-points", "VK_EXT_mesh_shader", "\"meshlet\":31"},
        Case{"--method sphere-mesh-tris --meshlet 15 --task-cull", "sphere-mesh-tris", "VK_EXT_mesh_shader",
             "\"task_cull\":true"},
        Case{"--method sphere-rt", "sphere-rt", "VK_KHR_ray_tracing_pipeline", "\"build_ms\""}}) {
    fs::path png = cliTempDir() / "mesh_rt.png";
    fs::remove(png);
    std::string args = std::string("render particles-drops --points 5k ") + c.args + " -o " + png.string() +
                       " --width 96 --height 64 --frames 1 --json -q";
    CliResult r = runPointrast(args);
    EXPECT_FALSE(r.signaled) << args;
    if (r.exitCode == 0) {
      std::printf("%s: rendered\n", c.method);
      EXPECT_TRUE(fs::exists(png));
      EXPECT_NE(r.out.find(std::string("\"method\":\"") + c.method + "\""), std::string::npos) << r.out;
      EXPECT_NE(r.out.find(c.jsonKey), std::string::npos) << r.out;
    } else {
      std::printf("%s: %s", c.method, r.err.c_str());
      EXPECT_EQ(r.exitCode, 1) << r.err;
      EXPECT_NE(r.err.find(std::string("pointrast: ") + c.method + " is not available on"), std::string::npos)
          << r.err;
      EXPECT_NE(r.err.find(c.extension), std::string::npos) << r.err;
      EXPECT_EQ(lineCount(r.err, "pointrast: "), 1u) << r.err;
      EXPECT_FALSE(fs::exists(png));
    }
  }
}

TEST(SpheresMeshRtCli, MeshOptionsAreChecked) {
  fs::path png = cliTempDir() / "bad_mesh.png";
  expectCleanFailure("render particles-block --points 1k --method sphere-mesh-tris --meshlet 16 -o " +
                         png.string(),
                     png, "--meshlet takes 31 or 15");
  expectCleanFailure("render particles-block --points 1k --method sphere-compute --task-cull -o " +
                         png.string(),
                     png, "apply to sphere-mesh-points and sphere-mesh-tris");
  expectCleanFailure("render particles-block --points 1k --method sphere-rt --meshlet 15 -o " + png.string(),
                     png, "apply to sphere-mesh-points and sphere-mesh-tris");
  expectCleanFailure("render terrain --points 1k --meshlet 15 -o " + png.string(), png,
                     "apply to sphere-mesh-points and sphere-mesh-tris");
}

} // namespace pointrast::test
