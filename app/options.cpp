#include "options.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "base/error.h"
#include "cli_util.h"
#include "render/clip_volumes.h"

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
  cmd.add_option(
         "--min-node-px", a.minNodePx,
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

void addStereoOptions(CLI::App& cmd, StereoArgs& a) {
  cmd.add_flag("--stereo", a.stereo,
               "Batch and LOD methods: render both eyes in one pass into one side-by-side image (left eye on "
               "the left); each point is read once and drawn into both eyes. render: each eye --width x "
               "--height; the viewers: each eye half the window or page");
  cmd.add_option("--ipd", a.ipd,
                 "Stereo: distance between the eyes in scene units (default: the convergence distance / 30, "
                 "comfortable whatever the units; 0.064 is life-size for a cloud in metres)");
  cmd.add_option("--convergence", a.convergence,
                 "Stereo: distance from the eye of the plane seen at zero parallax, in scene units (default: "
                 "the target's distance), or inf for parallel eyes as a VR headset renders");
  cmd.add_option("--stereo-layout", a.stereoLayout,
                 "Stereo output: side-by-side (left eye left), cross-eyed (right eye left, for cross-eyed "
                 "viewing) or, for render, separate (OUT-left.png and OUT-right.png)")
      ->capture_default_str();
  cmd.add_flag("--foveated", a.foveated,
               "LOD methods: foveated level of detail, nodes must look larger away from the image's centre "
               "(each eye's centre in stereo) to be drawn");
  cmd.add_option("--fovea-radius", a.foveaRadius,
                 "Foveated LOD: radius of the fovea in half-diagonals of the image (0..1, default 0.3); "
                 "inside it --min-node-px holds");
  cmd.add_option("--fovea-periphery", a.foveaPeriphery,
                 "Foveated LOD: --min-node-px is multiplied by this at the image's corners, growing linearly "
                 "from the fovea's edge (default 3: 100 px in the centre, 300 px at the corners)");
}

StereoSettings stereoSettings(const StereoArgs& a) {
  if (!a.stereo && (a.ipd || !a.convergence.empty() || a.stereoLayout != "side-by-side"))
    throw InputError("--ipd, --convergence and --stereo-layout need --stereo");
  StereoSettings s;
  if (!a.stereo) return s;
  if (a.stereoLayout != "side-by-side" && a.stereoLayout != "cross-eyed" && a.stereoLayout != "separate")
    throw InputError("unknown --stereo-layout '" + a.stereoLayout +
                     "'; choose side-by-side, cross-eyed or separate");
  if (a.ipd) {
    if (!(*a.ipd > 0) || !std::isfinite(*a.ipd))
      throw InputError("--ipd must be a distance > 0 in scene units");
    s.separation = *a.ipd;
  }
  if (!a.convergence.empty()) s.convergence = parseConvergence(a.convergence);
  s.crossed = a.stereoLayout == "cross-eyed";
  validateStereo(s);
  return s;
}

lod::Foveation foveation(const StereoArgs& a) {
  if (!a.foveated && (a.foveaRadius || a.foveaPeriphery))
    throw InputError("--fovea-radius and --fovea-periphery need --foveated");
  lod::Foveation f;
  f.enabled = a.foveated;
  if (a.foveaRadius) f.radius = *a.foveaRadius;
  if (a.foveaPeriphery) f.periphery = *a.foveaPeriphery;
  if (!(f.radius >= 0 && f.radius <= 1)) throw InputError("--fovea-radius must be between 0 and 1");
  if (!(f.periphery >= 1) || !std::isfinite(f.periphery))
    throw InputError("--fovea-periphery must be a factor >= 1");
  return f;
}

void addDrawOptions(CLI::App& cmd, DrawArgs& a) {
  cmd.add_option("--depth", a.depth,
                 "Depth encoding of the atomic methods: float (32-bit linear depth) or int40 (40-bit integer "
                 "computed in double precision)")
      ->capture_default_str();
  addLookOptions(cmd, a.look);
  addLodOptions(cmd, a.lod);
  addFilterOptions(cmd, a.filter);
  addStereoOptions(cmd, a.eyes);
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
  if (a.eyes.stereoLayout == "separate")
    throw InputError("the viewers show both eyes side by side: --stereo-layout takes side-by-side or "
                     "cross-eyed there");
  settings.stereo = a.eyes.stereo;
  settings.eyes = stereoSettings(a.eyes);
  settings.foveation = foveation(a.eyes);
  // The viewers draw clip volumes per frame; attribute filters and a highlight are folded in when a cloud
  // is loaded or uploaded, which render does and the viewers do not.
  settings.filter = pointFilter(a.filter);
  checkGpuClip(settings.filter);
  if (settings.filter.hasAttributeFilter() ||
      (settings.filter.hasClip() && settings.filter.clipMode == ClipMode::Highlight))
    throw InputError("the viewers draw clip volumes (--clip-box, --clip-polygon, --clip-mode inside or "
                     "outside); --classes, --returns, --intensity, --gps-time, --source-ids and --clip-mode "
                     "highlight apply to render");
}

namespace {

// "1,2.5,-3" -> numbers; InputError naming the option unless every item is a finite number.
std::vector<double> numberList(const std::string& text, const char* option, const char* expects) {
  std::vector<double> values;
  size_t at = 0;
  for (;;) {
    const size_t comma = text.find(',', at);
    const std::string item = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(v))
      throw InputError(std::string(option) + " expects " + expects + ", got '" + text + "'");
    values.push_back(v);
    if (comma == std::string::npos) return values;
    at = comma + 1;
  }
}

// "2,6,9" or "3-5,9": integers 0..max, each alone or as an inclusive range.
std::vector<uint32_t> integerList(const std::string& text, const char* option, uint32_t max) {
  const std::string expects = std::string(option) + " expects integers 0.." + std::to_string(max) +
                              " and ranges lo-hi separated by commas (e.g. 2,6,9 or 3-5), got '" + text + "'";
  auto number = [&](const std::string& item) {
    if (item.empty() || item.size() > 6 || item.find_first_not_of("0123456789") != std::string::npos)
      throw InputError(expects);
    const unsigned long v = std::stoul(item);
    if (v > max) throw InputError(expects);
    return uint32_t(v);
  };
  std::vector<uint32_t> values;
  size_t at = 0;
  for (;;) {
    const size_t comma = text.find(',', at);
    const std::string item = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    const size_t dash = item.find('-');
    if (dash == std::string::npos) {
      values.push_back(number(item));
    } else {
      const uint32_t lo = number(item.substr(0, dash)), hi = number(item.substr(dash + 1));
      if (lo > hi) throw InputError(expects);
      for (uint32_t v = lo; v <= hi; ++v)
        values.push_back(v);
    }
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
  return values;
}

std::pair<double, double> closedRange(const std::string& text, const char* option) {
  const std::vector<double> v = numberList(text, option, "lo,hi (two numbers, lo <= hi)");
  if (v.size() != 2 || !(v[0] <= v[1]))
    throw InputError(std::string(option) + " expects lo,hi (two numbers, lo <= hi), got '" + text + "'");
  return {v[0], v[1]};
}

} // namespace

void addFilterOptions(CLI::App& cmd, FilterArgs& a) {
  const char* group = "Filters";
  cmd.add_option("--clip-box", a.clipBoxes,
                 "Keep the points inside an axis-aligned box, xmin,ymin,zmin,xmax,ymax,zmax in the file's "
                 "coordinates (boundaries inside); repeat it for several boxes (their union), e.g. "
                 "--clip-box 100,200,0,150,260,40")
      ->group(group);
  cmd.add_option("--clip-polygon", a.clipPolygons,
                 "Keep the points inside a polygon in x/y, x1,y1,x2,y2,x3,y3[,...] (at least three "
                 "vertices, closed automatically, even-odd rule), extruded over every z unless --clip-z; "
                 "repeatable, e.g. --clip-polygon 0,0,10,0,5,8")
      ->group(group);
  cmd.add_option("--clip-z", a.clipZ, "zmin,zmax: the height range of every --clip-polygon")->group(group);
  cmd.add_option("--clip-mode", a.clipMode,
                 "inside (keep what the clip volumes hold), outside (keep the rest) or highlight (keep every "
                 "point; viewers mark the inside ones)")
      ->capture_default_str()
      ->group(group);
  cmd.add_option("--classes", a.classes,
                 "Keep these classification values, e.g. 2,6,9 or 1-5,9 (ASPRS: 2 ground, 6 building, 9 "
                 "water)")
      ->group(group);
  cmd.add_option("--returns", a.returns,
                 "all, first (return number 1), last (return number = number of returns) or only (single "
                 "returns); points without a return number fail first, last and only")
      ->capture_default_str()
      ->group(group);
  cmd.add_option("--intensity", a.intensity, "Keep intensities lo <= i <= hi, e.g. --intensity 100,4000")
      ->group(group);
  cmd.add_option("--gps-time", a.gpsTime, "Keep GPS times lo <= t <= hi, as the file stores them")
      ->group(group);
  cmd.add_option("--source-ids", a.sourceIds,
                 "Keep these point source ids (flight lines), e.g. 1,4,7 or 10-12")
      ->group(group);
}

PointFilter pointFilter(const FilterArgs& a) {
  PointFilter f;
  for (const std::string& text : a.clipBoxes) {
    const char* expects = "xmin,ymin,zmin,xmax,ymax,zmax (six numbers, each min <= max)";
    const std::vector<double> v = numberList(text, "--clip-box", expects);
    if (v.size() != 6 || !(v[0] <= v[3] && v[1] <= v[4] && v[2] <= v[5]))
      throw InputError(std::string("--clip-box expects ") + expects + ", got '" + text + "'");
    f.boxes.push_back({{v[0], v[1], v[2]}, {v[3], v[4], v[5]}});
  }
  for (const std::string& text : a.clipPolygons) {
    const char* expects = "x1,y1,x2,y2,x3,y3[,...] (at least three x,y vertices)";
    const std::vector<double> v = numberList(text, "--clip-polygon", expects);
    if (v.size() < 6 || v.size() % 2 != 0)
      throw InputError(std::string("--clip-polygon expects ") + expects + ", got '" + text + "'");
    ClipPolygon poly;
    for (size_t i = 0; i < v.size(); i += 2)
      poly.vertices.emplace_back(v[i], v[i + 1]);
    f.polygons.push_back(std::move(poly));
  }
  if (!a.clipZ.empty()) {
    if (f.polygons.empty()) throw InputError("--clip-z applies to --clip-polygon, which was not given");
    const auto [lo, hi] = closedRange(a.clipZ, "--clip-z");
    for (ClipPolygon& poly : f.polygons) {
      poly.zMin = lo;
      poly.zMax = hi;
    }
  }
  if (a.clipMode == "inside")
    f.clipMode = ClipMode::Inside;
  else if (a.clipMode == "outside")
    f.clipMode = ClipMode::Outside;
  else if (a.clipMode == "highlight")
    f.clipMode = ClipMode::Highlight;
  else
    throw InputError("--clip-mode expects inside, outside or highlight, got '" + a.clipMode + "'");
  if (!a.classes.empty()) {
    f.classes.emplace();
    for (uint32_t c : integerList(a.classes, "--classes", 255))
      f.classes->set(c);
  }
  if (a.returns == "all")
    f.returns = ReturnFilter::All;
  else if (a.returns == "first")
    f.returns = ReturnFilter::First;
  else if (a.returns == "last")
    f.returns = ReturnFilter::Last;
  else if (a.returns == "only")
    f.returns = ReturnFilter::Only;
  else
    throw InputError("--returns expects all, first, last or only, got '" + a.returns + "'");
  if (!a.intensity.empty()) f.intensity = closedRange(a.intensity, "--intensity");
  if (!a.gpsTime.empty()) f.gpsTime = closedRange(a.gpsTime, "--gps-time");
  if (!a.sourceIds.empty()) {
    f.sourceIds.emplace();
    for (uint32_t id : integerList(a.sourceIds, "--source-ids", 65535))
      f.sourceIds->push_back(uint16_t(id));
  }
  return f;
}

} // namespace pointrast::app
