// pointrast generate SCENE --points N -o OUT.las | OUT.mmpld
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "cli_util.h"
#include "cloud/generate.h"
#include "cloud/order.h"
#include "cloud/particles_generate.h"
#include "commands.h"
#include "io/particles/particles_io.h"
#include "io/writer.h"

namespace pointrast::app {

namespace {

struct GenerateArgs {
  std::string scene, output, points = "1M", order = "original", mmpld = "1.3", pointFormat = "auto";
  uint64_t seed = 1;
  float radius = 0.5f;
  bool perParticleRadius = false, quiet = false;
  // Options that apply to one kind of scene only, to refuse them for the other.
  CLI::Option *orderOption = nullptr, *radiusOption = nullptr, *perParticleOption = nullptr,
              *mmpldOption = nullptr, *pointFormatOption = nullptr;
};

int generatePoints(const GenerateArgs& a) {
  for (const CLI::Option* o : {a.radiusOption, a.perParticleOption, a.mmpldOption})
    if (o->count())
      throw InputError(o->get_name() + " applies to particle scenes (" + kParticleSceneNames + "), not to " +
                       a.scene);
  Scene scene = parseScene(a.scene);
  Order order = parseOrder(a.order);
  lasFlavorFor(a.output, 0); // refuse a non-LAS name before spending minutes generating
  if (a.pointFormat != "auto" && a.pointFormat != "2" && a.pointFormat != "3")
    throw InputError("--point-format expects auto, 2 or 3, got '" + a.pointFormat + "'");
  GenerateOptions options;
  options.points = parseCount(a.points, "--points");
  options.seed = a.seed;
  options.progress = !a.quiet;
  PointCloud cloud = generateScene(scene, options);
  reorder(cloud, order, a.seed);
  io::LasFlavor flavor = lasFlavorFor(a.output, cloud.size());
  // Point format 2 (26 B, no GPS time) keeps large benchmark inputs small; LAS 1.2 needs < 2^32 points.
  if (a.pointFormat != "auto" && flavor == io::LasFlavor::Las14Pf7)
    throw InputError("--point-format " + a.pointFormat +
                     " is LAS 1.2, which holds at most 4,294,967,295 points");
  if (a.pointFormat == "2") flavor = io::LasFlavor::Las12Pf2;
  io::writeLas(a.output, cloud, flavor);
  if (!a.quiet) std::printf("%s: %s points\n", a.output.c_str(), humanCount(double(cloud.size())).c_str());
  return 0;
}

int generateParticleScene(const GenerateArgs& a) {
  for (const CLI::Option* o : {a.orderOption, a.pointFormatOption})
    if (o->count())
      throw InputError(o->get_name() + " applies to point scenes (terrain, tls), not to " + a.scene);
  if (a.mmpld != "1.0" && a.mmpld != "1.3")
    throw InputError("--mmpld expects 1.0 or 1.3, got '" + a.mmpld + "'");
  if (std::filesystem::path(a.output).extension() != ".mmpld")
    throw InputError(a.output + ": particle scenes are written as MMPLD (a .mmpld name)");
  ParticleGenerateOptions options;
  options.particles = parseCount(a.points, "--points");
  options.seed = a.seed;
  options.radius = a.radius;
  options.perParticleRadius = a.perParticleRadius;
  options.progress = !a.quiet;
  ParticleSet set = generateParticles(parseParticleScene(a.scene), options);
  io::writeMmpld(a.output, set, a.mmpld == "1.0" ? io::MmpldVersion::V1_0 : io::MmpldVersion::V1_3);
  if (!a.quiet) std::printf("%s: %s particles\n", a.output.c_str(), humanCount(double(set.size())).c_str());
  return 0;
}

} // namespace

Command addGenerate(CLI::App& app) {
  auto a = std::make_shared<GenerateArgs>();
  CLI::App* cmd =
      app.add_subcommand("generate", "Generate a synthetic point cloud (LAS) or particle scene (MMPLD)");
  cmd->footer(
      "\nPoint scenes, written as LAS (positions quantized to 1 mm):\n"
      "  terrain            aerial LiDAR: ground, buildings, trees, in flight-strip order\n"
      "  tls                terrestrial scans from a few scanner positions, in scan-line order\n"
      "\n"
      "Particle scenes, written as MMPLD (MegaMol's particle format) for the sphere renderers, shaped\n"
      "after the data sets of \"Efficient Sphere Rendering Revisited\" (2023):\n"
      "  particles-block    a dense jittered lattice block between two vapor regions (like Riemann)\n"
      "  particles-drops    liquid droplets joined by filaments, in a vapor (like Drop and Fluid)\n"
      "  particles-laser    a crystal slab with a molten crater and ejected clusters (like Laser ablation)\n"
      "  particles-uniform  uniform random in a cube, for scaling measurements\n"
      "Lengths are in units of the dense phase's atom spacing, so the default --radius 0.5 makes\n"
      "neighbors touch; a scene grows with --points. Colors follow phase and speed (Turbo ramp).\n"
      "--per-particle-radius varies the radius by kind around --radius (gas atoms smaller) and stores\n"
      "it per particle (FLOAT_XYZR: 20 B instead of 16 B per particle, in memory and on disk).\n"
      "\n"
      "Every scene is deterministic for a given seed, whatever the number of cores.\n"
      "\n"
      "Examples:\n"
      "  pointrast generate terrain --points 100M -o terrain100m.las\n"
      "  pointrast generate particles-laser --points 30M -o laser30m.mmpld\n"
      "  pointrast generate particles-drops --points 4M --per-particle-radius --seed 7 -o drops.mmpld\n"
      "  pointrast info laser30m.mmpld");
  cmd->add_option("SCENE", a->scene, "terrain, tls, or a particle scene (particles-block, ...)")->required();
  cmd->add_option("-o,--output", a->output, "LAS file (point scenes) or MMPLD file (particle scenes)")
      ->required();
  cmd->add_option("--points", a->points, "Number of points or particles (e.g. 5M, 1.2G)")
      ->capture_default_str();
  cmd->add_option("--seed", a->seed, "Random seed")->capture_default_str();
  a->orderOption = cmd->add_option("--order", a->order, "Point scenes: vertex order of the written file")
                       ->capture_default_str();
  a->pointFormatOption =
      cmd->add_option(
             "--point-format", a->pointFormat,
             "Point scenes: LAS point format, auto (3, or 7 past 2^32-1 points), 3 or 2 (no GPS time, 26 B)")
          ->capture_default_str();
  a->radiusOption =
      cmd->add_option("--radius", a->radius, "Particle scenes: sphere radius")->capture_default_str();
  a->perParticleOption = cmd->add_flag("--per-particle-radius", a->perParticleRadius,
                                       "Particle scenes: a radius per particle, varying around --radius");
  a->mmpldOption = cmd->add_option("--mmpld", a->mmpld, "Particle scenes: MMPLD version, 1.0 or 1.3")
                       ->capture_default_str();
  cmd->add_flag("-q,--quiet", a->quiet, "No progress lines");
  return [a] {
    Progress::setEnabled(!a->quiet);
    if (isParticleSceneName(a->scene)) return generateParticleScene(*a);
    if (!isSceneName(a->scene))
      throw InputError("unknown scene '" + a->scene +
                       "' (point scenes: terrain, tls; particle scenes: " + kParticleSceneNames + ")");
    return generatePoints(*a);
  };
}

} // namespace pointrast::app
