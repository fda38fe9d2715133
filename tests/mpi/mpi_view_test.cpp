// The desktop viewer on several ranks: `mpirun -np 2 pointrast view` on a private Xvfb, driven as the
// window tests drive it. Rank 0's window shows what one process shows: every rank draws its half of the
// file and the words are composited on rank 0.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "mpi/mpi_harness.h"
#include "web/image_compare.h"
#include "window/viewer_harness.h"

namespace fs = std::filesystem;
using namespace pointrast::test;
using namespace pointrast::test::mpi;

namespace {

const std::string kCamera = " --eye 636300,848700,900 --target 636600,849200,450 --up 0,0,1 --fov 60";
const std::string kSize = " --width 480 --height 360";

// The file a viewer's F12 wrote (its screenshot folder is `dir`), and its exit status after Escape.
struct Shot {
  std::string png;
  int status = -1;
  nlohmann::json exit;
};

Shot screenshot(const std::string& display, const std::string& args, const fs::path& dir,
                const std::string& launcher = "") {
  fs::remove_all(dir);
  fs::create_directories(dir);
  Shot shot;
  Viewer viewer(display,
                args + " --screenshot-dir '" + dir.string() + "' --path '" + (dir / "path.json").string() +
                    "'",
                launcher);
  if (!viewer.waitEvent("frame", 0, 180)) {
    ADD_FAILURE() << "no frame shown\n" << viewer.errors();
    return shot;
  }
  // One window, whatever the ranks: rank 0's.
  EXPECT_EQ(shellOutput("DISPLAY=" + display + " xdotool search --name '^pointrast' 2>/dev/null | wc -l"),
            "1\n");
  viewer.xdotool("mousemove --window $W 200 200 key F12");
  const auto taken = viewer.waitEvent("screenshot", 0, 60);
  EXPECT_TRUE(taken) << viewer.errors();
  if (taken) shot.png = (*taken)["file"].get<std::string>();
  shot.status = viewer.quit();
  if (auto exit = viewer.waitEvent("exit", 0, 5)) shot.exit = *exit;
  EXPECT_EQ(shot.status, 0) << viewer.errors();
  return shot;
}

TEST(MpiView, TwoRanksShowTheFrameOfOneProcessAndEndTogether) {
  REQUIRE_MPI();
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  Xvfb xvfb;
  ASSERT_FALSE(xvfb.display().empty()) << "Xvfb did not start (scripts/install-deps.sh installs xvfb)";
  const std::string file = (dataDir() / "las" / "autzen_trim.las").string();
  const std::string args = "'" + file + "'" + kCamera + kSize + " --method atomicmin --no-panel";
  const Shot one = screenshot(xvfb.display(), args, cliTempDir() / "view_one");
  const Shot two = screenshot(xvfb.display(), args, cliTempDir() / "view_two", mpirun(2));
  ASSERT_FALSE(one.png.empty());
  ASSERT_FALSE(two.png.empty());
  // Closest points composite exactly: the same pixels as one process, and as `render` of the whole file.
  const ImageDifference d = comparePngs(one.png, two.png);
  EXPECT_TRUE(d.sameSize);
  EXPECT_EQ(d.psnr, 99) << "mean absolute difference " << d.meanAbs;
  const fs::path reference = cliTempDir() / "view_reference.png";
  const CliResult rendered =
      runPointrast("render '" + file + "'" + kCamera + kSize + " --method atomicmin --frames 1 -q -o '" +
                   reference.string() + "'");
  ASSERT_EQ(rendered.exitCode, 0) << rendered.err;
  EXPECT_EQ(comparePngs(two.png, reference.string()).psnr, 99);
  ASSERT_TRUE(two.exit.is_object());
  EXPECT_EQ(two.exit["validation_errors"].get<int>(), 0);
}

} // namespace
