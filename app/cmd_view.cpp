// pointrast view [FILE|SCENE]: the desktop viewer.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "report/run_json.h"
#include "view/stats_report.h"
#include "cli_util.h"
#include "commands.h"
#include "distributed.h"
#include "distributed_serve.h"
#include "input.h"
#include "options.h"
#include "io/annotations_file.h"
#include "io/format_table.h"
#include "mpi/mpi_job.h"
#include "view/desktop/viewer.h"
#include "view/flight.h"

namespace pointrast::app {

namespace {

struct ViewArgs {
  std::string input, eye, target, up = "0,0,1", background = "0,0,0", order = "original";
  std::string method, points = "1M", path = "path.json", screenshots = ".", stats;
  std::string annotations; // --annotations: measurements loaded and saved
  uint32_t width = 1280, height = 720;
  double fov = 60;
  double flight = 0, flightRate = 120; // --flight SECONDS: a scripted flight (view/flight.h), then close
  uint64_t seed = 1;
  std::optional<uint32_t> device;
  bool noPanel = false, noVsync = false, events = false, quiet = false;
  DrawArgs draw; // look, level of detail, depth: as render's
};

// Said before the window opens, so a session's statistics are not lost to a folder that is not there.
void checkStatsFile(const std::string& stats) {
  if (stats.empty() || stats == "-") return;
  std::filesystem::path parent = std::filesystem::path(stats).parent_path();
  std::error_code error;
  if (!parent.empty() && !std::filesystem::is_directory(parent, error))
    throw InputError(stats + ": --stats names a file in a folder that does not exist");
  if (std::filesystem::is_directory(stats, error))
    throw InputError(stats + ": --stats names a folder; give the JSON file to write");
}

// The statistics of every frame the session rendered, as one JSON document (a file written whole, or one
// line on stdout for `-`).
void writeStats(const ViewArgs& a, const view::SceneInput& input, const view::FrameLog& log,
                const view::ViewerOptions& options, const view::Flight* flight) {
  report::ReportInfo info;
  std::filesystem::path file(a.stats);
  info.name = a.stats == "-" ? "view" : file.stem().string();
  info.title = "pointrast view: " + input.name;
  info.commandLine = commandLine("pointrast view");
  info.date = report::utcNow();
  const nlohmann::json j =
      view::viewStatsJson(log, {input.name, input.points, options.vsync, options.panel}, info, flight);
  if (a.stats == "-")
    std::printf("%s\n", jsonText(j).c_str());
  else
    report::writeAtomically(file, report::jsonFileText(j));
}

int runView(const ViewArgs& a) {
  // Said before anything is loaded: there is no window to show it in (under mpirun only rank 0 opens one).
  if ((!distributedRun() || mpi::Job::get().root()) && !view::hasDisplay())
    throw InputError("no display to open a window on (DISPLAY and WAYLAND_DISPLAY are unset): view in a "
                     "browser with `pointrast serve`, or render images with `pointrast render`");
  Progress::setEnabled(!a.quiet);
  view::ViewerOptions options;
  options.width = a.width;
  options.height = a.height;
  options.vsync = !a.noVsync;
  options.panel = !a.noPanel;
  options.events = a.events;
  options.fovY = a.fov;
  if (!a.method.empty()) options.method = parseMethod(a.method);
  options.settings.background = parseRgb(a.background, "--background");
  applyDrawOptions(a.draw, options.settings);
  options.pathFile = a.path;
  options.annotationsFile = a.annotations;
  options.inputFile = a.input;
  // A file given but damaged is said now, not after the window opened.
  std::error_code exists;
  if (!a.annotations.empty() && std::filesystem::exists(a.annotations, exists)) io::loadAnnotations(a.annotations);
  options.screenshotDir = a.screenshots;
  options.device = a.device;
  if (!a.target.empty() && a.eye.empty()) throw InputError("--target needs --eye");
  checkStatsFile(a.stats);
  std::optional<view::Flight> flight;
  if (a.flight == 0 && a.flightRate != 120) throw InputError("--flight-rate needs --flight SECONDS");
  if (a.flight != 0) flight.emplace(view::FlightOptions{a.flight, a.flightRate});
  if (flight) options.flight = &*flight;
  const InputSpec spec = inputSpec(a.input, a.points, a.seed, a.order, a.quiet);
  checkSceneMethod(spec, options.method);
  view::FrameLog log;
  if (!a.stats.empty()) options.frameLog = &log;

  SceneOptions scene;
  scene.method = options.method;
  scene.gpuBudget = options.settings.gpuMemory;
  scene.onNote = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  auto show = [&](view::SceneInput& input) {
    if (auto camera = cameraFromOptions(a.eye, a.target, a.up, a.fov, input.bounds.center()))
      options.camera = camera;
    options.title = "pointrast - " + input.name;
    const int status = view::runViewer(input, options);
    if (!a.stats.empty()) writeStats(a, input, log, options, flight ? &*flight : nullptr);
    if (flight) {
      std::fprintf(stderr, "%s\n", flight->summary().c_str());
      if (const std::string why = flight->emptyStrokes(); !why.empty() && status == 0) {
        std::fprintf(stderr, "pointrast: %s\n", why.c_str());
        return 1;
      }
    }
    return status;
  };
  // Under mpirun (docs/mpi.md): rank 0 opens the window and every rank draws its share of each frame.
  if (distributedRun())
    return runViewerRanks(options.method, options.device, a.quiet, options.settings, spec, scene,
                          [&](view::SceneInput& input, SourceMaker make) {
                            options.makeSource = std::move(make);
                            return show(input);
                          });
  view::SceneInput input = openScene(spec, scene);
  return show(input);
}

} // namespace

Command addView(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  CLI::App* cmd =
      app.add_subcommand("view", "View a point cloud in a window (GLFW + Vulkan), with a settings panel");
  cmd->footer(
      "\nMouse: left drag orbits around the pivot, right or middle drag pans, the wheel zooms towards the\n"
      "point under the cursor, a double-click makes the clicked point the pivot; Ctrl+click picks the point\n"
      "under the cursor (its attributes in the panel), Ctrl+Shift+click adds it to a measurement (the\n"
      "panel's kind: distance, height or area); Ctrl+S saves the measurements to --annotations.\n"
      "Keys: W A S D Q E fly (Shift: faster); 8 2 5 0 4 6 top, bottom, front, back, left, right views,\n"
      "1 the overview's direction; F frames the whole cloud; K records a keyframe (saved to --path at "
      "once);\n"
      "C prints the camera as render options; F12 writes a screenshot; H hides the panel; Escape quits.\n"
      "Keyframes render to a video with `pointrast render FILE --path path.json --video out.mp4`.\n"
      "--stats writes, as the window closes, the median and 95th percentile GPU time of each pass\n"
      "(render: clear + draw + resolve; present: the image into the window, and the panel) and of the\n"
      "frame over every frame rendered, the host's frame time, the device and the commit (JSON).\n"
      "Without a display, use `pointrast serve` (a browser) or `pointrast render` (images).\n"
      "Under mpirun (one rank per GPU, docs/mpi.md) rank 0 opens the window and every rank draws its share\n"
      "of each frame (its share of a file's points, or of each frame's octree nodes), composited on rank 0;\n"
      "methods whose frames cannot be composited are left out of the panel, and the pick tool is off.\n\n"
      "Examples:\n"
      "  pointrast view autzen.las\n"
      "  pointrast view autzen_octree/              # an octree: streamed with level of detail (lod)\n"
      "  pointrast view lone-star.copc.laz --method lod-hqs\n"
      "  pointrast view terrain --points 10M --method batch-prefetch\n"
      "  pointrast view autzen.las --eye 636000,848900,700 --target 636600,849200,450 --no-panel\n"
      "  pointrast view terrain --points 10M --no-vsync --stats view.json  # then drag, and Escape\n"
      "  pointrast view octree/ --no-vsync --flight 15 --stats flight.json # flies, measures, closes\n"
      "  mpirun -np 2 pointrast view big_octree/                    # two GPUs draw each frame");
  cmd->add_option("FILE", a->input,
                  "A cloud file (" + io::formatList(io::FormatUse::Cloud) + "), an octree (" +
                      io::formatList(io::FormatUse::Octree) +
                      ", streamed with level of detail), or a scene name (terrain, tls); default: the demo "
                      "scene");
  cmd->add_option("--width", a->width, "Window width in pixels")->capture_default_str();
  cmd->add_option("--height", a->height, "Window height in pixels")->capture_default_str();
  cmd->add_option("--eye", a->eye, "Starting camera position x,y,z (default: overview)");
  cmd->add_option("--target", a->target, "Point looked at x,y,z (default: center of the bounds)");
  cmd->add_option("--up", a->up, "Up direction x,y,z")->capture_default_str();
  cmd->add_option("--fov", a->fov, "Vertical field of view in degrees")->capture_default_str();
  cmd->add_option("--method", a->method,
                  "Rasterization method (changeable in the panel); default: lod for an octree, else the "
                  "fastest for the device (batch-prefetch on a discrete GPU, atomicmin elsewhere)");
  cmd->add_option("--background", a->background, "Background color r,g,b (0..255)")->capture_default_str();
  addDrawOptions(*cmd, a->draw);
  cmd->add_option("--order", a->order, "Vertex order: original, morton, shuffled, shuffled-morton")
      ->capture_default_str();
  cmd->add_option("--points", a->points, "Points of a generated scene (e.g. 1M, 100M)")
      ->capture_default_str();
  cmd->add_option("--seed", a->seed, "Seed for generated scenes and shuffled orders")->capture_default_str();
  cmd->add_option("--annotations", a->annotations,
                 "Measurements file (JSON): loaded when it exists, drawn in the panel, written by Ctrl+S");
  cmd->add_option("--path", a->path, "Keyframes file: loaded when it exists, written on every K")
      ->capture_default_str();
  cmd->add_option("--screenshot-dir", a->screenshots, "Folder of F12 screenshots (pointrast-0001.png, ...)")
      ->capture_default_str();
  cmd->add_flag("--no-panel", a->noPanel, "Start with the panel hidden (H toggles it)");
  cmd->add_flag("--no-vsync", a->noVsync, "Present as fast as frames come instead of at the display's rate");
  cmd->add_flag(
      "--events", a->events,
      "Print one JSON object a line on stdout for every frame shown and every action (for scripts)");
  cmd->add_option("--stats", a->stats,
                  "At the close, write the GPU time per pass and per frame over the frames rendered to "
                  "this JSON file (- for one line on stdout)");
  cmd->add_option(
      "--flight", a->flight,
      "Fly a scripted flight for this many seconds, then close: wheel steps down low, pan strokes "
      "across the cloud, then eight jumps, each until its view converged; --stats and --events "
      "get frames/s, input to frame and frames to converge");
  cmd->add_option("--flight-rate", a->flightRate, "Inputs a second during the flight's strokes")
      ->capture_default_str();
  cmd->add_option("--device", a->device, "Vulkan device index (see `pointrast info --devices`)");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress lines");
  return [a] { return runView(*a); };
}

} // namespace pointrast::app
