// The command-line options that describe how points look and how octrees are drawn, declared once and
// shared by render, view and serve: whatever render can draw, the viewers can show.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cloud/attribute_colors.h"
#include "cloud/point_filter.h"
#include "render/lod/foveation.h"
#include "render/post/post_settings.h"
#include "render/stereo.h"
#include "view/session.h"

namespace pointrast::app {

// Colors, point size, hole filling and eye-dome lighting (the resolve stage).
struct LookArgs {
  std::string color = "auto", colorRange;
  float pointSize = 1, pointSizeMax = 16;
  std::string pointShape = "square", pointSizeMode = "fixed";
  uint32_t dilate = 0;
  bool edl = false;
  std::optional<float> edlStrength, edlRadius;
};
void addLookOptions(CLI::App& cmd, LookArgs& a);

// --point-size, --point-shape, --point-size-mode, --point-size-max, --dilate, --edl*: checked, InputError
// naming the option otherwise.
PostSettings postSettings(const LookArgs& a);

// --color and --color-range as given: no source for auto (displayColorMode's choice).
struct ColorChoice {
  std::optional<DisplayColorMode::Source> source;
  std::optional<ColorRange> range;
};
ColorChoice colorChoice(const LookArgs& a);

// Level of detail (the LOD methods).
struct LodArgs {
  double minNodePx = 100;
  std::string pointBudget = "0"; // 0: no limit
  std::string gpuMemory;         // node cache budget; empty: half the device
  bool given = false;            // one of the three was given
};
void addLodOptions(CLI::App& cmd, LodArgs& a);
// Checked values: --min-node-px >= 0, counts and byte sizes (InputError naming the option otherwise).
struct LodValues {
  double minNodePx = 100;
  uint64_t pointBudget = 0;
  uint64_t gpuBytes = 0; // 0: the default
};
LodValues lodValues(const LodArgs& a);

// Stereo (batch and LOD methods) and foveated level of detail (LOD methods): render draws them into its
// PNG(s), the viewers into the window or page (both eyes side by side, each half as wide).
struct StereoArgs {
  bool stereo = false;
  std::optional<double> ipd;
  std::string convergence, stereoLayout = "side-by-side";
  bool foveated = false;
  std::optional<double> foveaRadius, foveaPeriphery;
};
void addStereoOptions(CLI::App& cmd, StereoArgs& a);
// --stereo and its options; throws InputError for stereo options without --stereo and bad values.
StereoSettings stereoSettings(const StereoArgs& a);
// --foveated and its options; throws InputError for fovea options without --foveated and bad values.
lod::Foveation foveation(const StereoArgs& a);

// Which points to keep (convert, profile) or show (the renderers): clip volumes and attribute filters,
// one "Filters" group of options. Oriented boxes have no option: they come from annotation files, added
// to the PointFilter that pointFilter() returns.
struct FilterArgs {
  std::vector<std::string> clipBoxes, clipPolygons;
  std::string clipZ, clipMode = "inside";
  std::string classes, returns = "all", intensity, gpsTime, sourceIds;
};
void addFilterOptions(CLI::App& cmd, FilterArgs& a);
// The options as a PointFilter; InputError naming the option on bad text.
PointFilter pointFilter(const FilterArgs& a);

// The options every command that draws points shares with render, beyond the input and the camera: the
// look, level of detail, --depth and the filters. The viewers start from them (every one stays changeable in
// the panel).
struct DrawArgs {
  LookArgs look;
  LodArgs lod;
  std::string depth = "float";
  FilterArgs filter; // the Filters group: the viewers draw its clip volumes
  StereoArgs eyes;   // stereo and foveated LOD
};
void addDrawOptions(CLI::App& cmd, DrawArgs& a);
// The options as a viewer's starting settings (the method aside). Throws InputError naming the option.
void applyDrawOptions(const DrawArgs& a, view::ViewSettings& settings);

} // namespace pointrast::app
