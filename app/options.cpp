#include "options.h"

#include "base/error.h"
#include "cli_util.h"

namespace pointrast::app {

void addLookOptions(CLI::App& cmd, LookArgs& a) {
  cmd.add_option("--color", a.color,
                 "Point colors: auto (RGB if the file has it, else intensity, else elevation), rgb, "
                 "intensity, classification (ASPRS classes), elevation, return (return number), source "
                 "(point source id)")
      ->capture_default_str();
  cmd.add_option("--color-range", a.colorRange,
                 "lo,hi mapped to the ends of the intensity or elevation ramp (default: the 0.5 % and 99.5 % "
                 "percentiles)");
  cmd.add_option("--point-size", a.pointSize,
                 "Point size in pixels (1..32); the closest point still wins every pixel")
      ->capture_default_str();
  cmd.add_option("--point-shape", a.pointShape, "Shape of points larger than a pixel: square or disc")
      ->capture_default_str();
  cmd.add_option("--point-size-mode", a.pointSizeMode,
                 "fixed (every point --point-size pixels) or attenuated (--point-size pixels at the target's "
                 "distance, larger nearer and smaller farther, at most --point-size-max)")
      ->capture_default_str();
  cmd.add_option("--point-size-max", a.pointSizeMax, "Attenuated point sizes: the largest, pixels (1..32)")
      ->capture_default_str();
  cmd.add_option("--dilate", a.dilate,
                 "Fill holes up to R pixels wide with the closest point around them (0..8; 0: off); a far "
                 "point never covers a near one, and convex outlines do not grow")
      ->capture_default_str();
  cmd.add_flag("--edl", a.edl,
               "Eye-dome lighting (as Potree): shade each point by how far it lies behind "
               "its neighbours");
  cmd.add_option("--edl-strength", a.edlStrength, "Eye-dome lighting strength (default 1; implies --edl)");
  cmd.add_option("--edl-radius", a.edlRadius,
                 "Eye-dome lighting: distance of the 8 neighbours in pixels (default 1.4; implies --edl)");
}

PostSettings postSettings(const LookArgs& a) {
  PostSettings post;
  post.pointSize = a.pointSize;
  post.shape = parsePointShape(a.pointShape);
  post.sizeMode = parsePointSizeMode(a.pointSizeMode);
  post.maxPointSize = a.pointSizeMax;
  post.dilate = a.dilate;
  // --edl-strength or --edl-radius alone turn eye-dome lighting on, with Potree's defaults for the other.
  if (a.edl || a.edlStrength || a.edlRadius) {
    post.edlStrength = a.edlStrength.value_or(1.0f);
    post.edlRadius = a.edlRadius.value_or(post.edlRadius);
  }
  validatePostSettings(post);
  return post;
}

ColorChoice colorChoice(const LookArgs& a) {
  ColorChoice choice;
  if (a.color == "auto") {
    if (!a.colorRange.empty()) throw InputError("--color-range applies to --color intensity and elevation");
    return choice;
  }
  choice.source = parseColorSource(a.color);
  if (!a.colorRange.empty()) {
    if (choice.source != DisplayColorMode::Source::Intensity &&
        choice.source != DisplayColorMode::Source::Elevation)
      throw InputError("--color-range applies to --color intensity and elevation, not " + a.color);
    auto [lo, hi] = parseRange(a.colorRange, "--color-range");
    choice.range = ColorRange{lo, hi};
  }
  return choice;
}

void addLodOptions(CLI::App& cmd, LodArgs& a) {
  auto given = [&a](const std::string&) { a.given = true; };
  cmd.add_option("--min-node-px", a.minNodePx,
                 "LOD methods: skip octree nodes whose projected size (the pixel radius of the node's bounding "
                 "sphere) is smaller, with their subtrees; 0 draws every point")
      ->capture_default_str()
      ->each(given);
  cmd.add_option("--point-budget", a.pointBudget,
                 "LOD methods: most points drawn, largest nodes first (e.g. 100M; 0: no limit)")
      ->capture_default_str()
      ->each(given);
  cmd.add_option("--gpu-memory", a.gpuMemory,
                 "LOD methods: GPU memory for the node cache (e.g. 8G; default: half the device's); a larger "
                 "selection is drawn in several passes (render) or as far as it fits (the viewers)")
      ->each(given);
}

LodValues lodValues(const LodArgs& a) {
  LodValues v;
  if (!(a.minNodePx >= 0)) throw InputError("--min-node-px must be 0 or more");
  v.minNodePx = a.minNodePx;
  v.pointBudget = parseCount(a.pointBudget, "--point-budget");
  if (!a.gpuMemory.empty()) v.gpuBytes = parseBytes(a.gpuMemory, "--gpu-memory");
  return v;
}

void addDrawOptions(CLI::App& cmd, DrawArgs& a) {
  cmd.add_option("--depth", a.depth,
                 "Depth encoding of the atomic methods: float (32-bit linear depth) or int40 (40-bit integer "
                 "computed in double precision)")
      ->capture_default_str();
  addLookOptions(cmd, a.look);
  addLodOptions(cmd, a.lod);
}

void applyDrawOptions(const DrawArgs& a, view::ViewSettings& settings) {
  settings.depth = parseDepthMode(a.depth);
  settings.post = postSettings(a.look);
  const ColorChoice colors = colorChoice(a.look);
  settings.colorSource = colors.source;
  settings.colorRange = colors.range;
  const LodValues lod = lodValues(a.lod);
  settings.minNodePx = lod.minNodePx;
  settings.pointBudget = lod.pointBudget;
  settings.gpuMemory = lod.gpuBytes;
}

} // namespace pointrast::app
