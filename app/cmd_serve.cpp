// pointrast serve [FILE|SCENE]: the browser viewer.
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "cli_util.h"
#include "commands.h"
#include "distributed.h"
#include "distributed_serve.h"
#include "input.h"
#include "io/annotations_file.h"
#include "io/format_table.h"
#include "options.h"
#include "view/web/server.h"

namespace pointrast::app {

namespace {

struct ServeArgs {
  std::string input, eye, target, up = "0,0,1", background = "0,0,0", order = "original";
  std::string annotations; // --annotations: the measurement list each page starts with
  std::string method, points = "1M", bind = "127.0.0.1", token, maxSize = "3840x2160", frameAncestors;
  uint32_t port = 8080, maxClients = view::web::kDefaultMaxClients;
  double fov = 60, motionScale = 0.5;
  int quality = 90, motionQuality = 60;
  uint64_t seed = 1;
  std::optional<uint32_t> device;
  bool events = false, quiet = false;
  DrawArgs draw; // look, level of detail, depth: as render's
};

// "1920x1080" -> viewport.
view::Viewport parseSize(const std::string& text) {
  unsigned w = 0, h = 0;
  char x = 0, rest = 0;
  if (std::sscanf(text.c_str(), "%u%c%u%c", &w, &x, &h, &rest) != 3 || (x != 'x' && x != 'X'))
    throw InputError("--max-size " + text + ": give WIDTHxHEIGHT, e.g. 1920x1080");
  return {w, h};
}

// `mpirun -np N pointrast serve` (docs/mpi.md): rank 0 serves the page and draws every frame with all
// ranks (distributed_serve.h), the others follow its draws until it stops.
int serveRanks(const ServeArgs& a, view::web::ServerOptions& o, const InputSpec& spec,
               const SceneOptions& scene) {
  return runViewerRanks(
      o.method, o.device, a.quiet, o.settings, spec, scene, [&](view::SceneInput& input, SourceMaker make) {
        if (auto camera = cameraFromOptions(a.eye, a.target, a.up, a.fov, input.bounds.center()))
          o.camera = camera;
        o.announceDevice = false; // one line per rank instead
        o.makeSource = std::move(make);
        return view::web::runServer(input, o);
      });
}

int runServe(const ServeArgs& a) {
  Progress::setEnabled(!a.quiet);
  view::web::ServerOptions o;
  o.bind = a.bind;
  if (a.port > 65535) throw InputError("--port takes 0 to 65535");
  o.port = uint16_t(a.port);
  o.token = a.token;
  o.frameAncestors = a.frameAncestors;
  o.maxClients = a.maxClients;
  o.maxSize = parseSize(a.maxSize);
  o.fovY = a.fov;
  if (!a.method.empty()) o.method = parseMethod(a.method);
  o.settings.background = parseRgb(a.background, "--background");
  applyDrawOptions(a.draw, o.settings);
  if (!(a.motionScale >= 0.25 && a.motionScale <= 1)) throw InputError("--motion-scale takes 0.25 to 1");
  if (a.quality < 10 || a.quality > 100 || a.motionQuality < 10 || a.motionQuality > 100)
    throw InputError("--quality and --motion-quality take 10 to 100");
  o.stream = {a.motionScale, a.quality, a.motionQuality};
  o.device = a.device;
  o.events = a.events;
  o.quiet = a.quiet;
  if (!a.target.empty() && a.eye.empty()) throw InputError("--target needs --eye");
  if (!a.annotations.empty()) o.annotations = io::loadAnnotations(a.annotations);
  view::web::checkServerOptions(o);
  const InputSpec spec = inputSpec(a.input, a.points, a.seed, a.order, a.quiet);
  checkSceneMethod(spec, o.method);
  o.inputFile = spec.source;

  SceneOptions scene;
  scene.method = o.method;
  scene.gpuBudget = o.settings.gpuMemory;
  scene.onNote = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  if (distributedRun()) return serveRanks(a, o, spec, scene);
  view::SceneInput input = openScene(spec, scene);
  if (auto camera = cameraFromOptions(a.eye, a.target, a.up, a.fov, input.bounds.center())) o.camera = camera;
  return view::web::runServer(input, o);
}

} // namespace

Command addServe(CLI::App& app) {
  auto a = std::make_shared<ServeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "serve", "View a point cloud in a web browser: rendered on this machine's GPU, streamed as JPEG");
  cmd->footer(
      "\nListens on 127.0.0.1 (this machine only) unless --bind says otherwise; any other address needs an\n"
      "access token, generated and printed in the URL unless --token gives one. Reach a remote server\n"
      "through an SSH tunnel (ssh -L 8080:localhost:8080 HOST, then open http://localhost:8080/) or a TLS\n"
      "reverse proxy. The page navigates like `pointrast view`: left drag orbits, right or middle drag "
      "pans,\n"
      "the wheel zooms, a double-click sets the pivot, W A S D Q E fly, 8 2 5 0 4 6 1 views, F frames all;\n"
      "on touch screens one finger orbits, two pan and pinch zooms. Ctrl-C (SIGINT) or SIGTERM stops it.\n"
      "Limits: a client's frame is at most 3840x2160 samples (width x height x supersample^2: 4K at 1,\n"
      "1080p at 2, 960x540 at 4); a connection that sends no request within 3 s is closed, and up to 128\n"
      "such connections delay no page load.\n"
      "Under mpirun (one rank per GPU, docs/mpi.md) rank 0 serves the page and every rank draws its\n"
      "share of each frame (a cloud's points, an octree's nodes), composited on rank 0: the closest-point\n"
      "methods only, and the pick tool and measuring run on one process. The other ranks open no socket\n"
      "and exit with rank 0's status: stop the job by signalling rank 0 (the pid of --events' listening\n"
      "line); mpirun, signalled itself, ends the job with its own status.\n\n"
      "Examples:\n"
      "  pointrast serve autzen.las                                   # http://127.0.0.1:8080/\n"
      "  pointrast serve lone-star.copc.laz                           # an octree, streamed (lod)\n"
      "  pointrast serve terrain --points 1G --method batch-prefetch --port 9000\n"
      "  pointrast serve cloud.las --bind 0.0.0.0 --max-clients 8     # prints http://HOST:8080/?token=...\n"
      "  mpirun -np 2 pointrast serve big_octree/                     # two GPUs draw each frame");
  cmd->add_option("FILE", a->input,
                  "A cloud file (" + io::formatList(io::FormatUse::Cloud) + "), an octree (" +
                      io::formatList(io::FormatUse::Octree) +
                      ", streamed with level of detail), or a scene name (terrain, tls); default: the demo "
                      "scene");
  cmd->add_option("--port", a->port, "TCP port (0: any free port, printed)")->capture_default_str();
  cmd->add_option("--bind", a->bind,
                  "Address to listen on; anything but 127.0.0.1, ::1 or localhost needs a token")
      ->capture_default_str();
  cmd->add_option("--token", a->token, "Access token clients must present (16-100 letters, digits, - or _)");
  cmd->add_option("--max-clients", a->maxClients, "Browser tabs served at once")->capture_default_str();
  cmd->add_option("--frame-ancestors", a->frameAncestors,
                  "Pages allowed to show the viewer in a frame, as origins separated by spaces (e.g. "
                  "\"http://localhost:*\"; default: none). pointrast.show() uses it to embed the viewer in "
                  "a Jupyter notebook");
  cmd->add_option("--max-size", a->maxSize, "Largest frame WxH (a larger canvas is drawn scaled up)")
      ->capture_default_str();
  cmd->add_option("--quality", a->quality, "JPEG quality of the full frame at rest")->capture_default_str();
  cmd->add_option("--motion-quality", a->motionQuality, "JPEG quality while the camera moves")
      ->capture_default_str();
  cmd->add_option("--motion-scale", a->motionScale,
                  "Frame side while the camera moves, relative to the canvas")
      ->capture_default_str();
  cmd->add_option("--annotations", a->annotations,
                 "Annotations file (JSON) whose measurements every page starts with, drawn over the frames");
  cmd->add_option("--eye", a->eye, "Starting camera position x,y,z (default: overview)");
  cmd->add_option("--target", a->target, "Point looked at x,y,z (default: center of the bounds)");
  cmd->add_option("--up", a->up, "Up direction x,y,z")->capture_default_str();
  cmd->add_option("--fov", a->fov, "Vertical field of view in degrees")->capture_default_str();
  cmd->add_option("--method", a->method,
                  "Rasterization method (changeable in the page); default: lod for an octree, else the "
                  "fastest for the device (batch-prefetch on a discrete GPU, atomicmin elsewhere)");
  cmd->add_option("--background", a->background, "Background color r,g,b (0..255)")->capture_default_str();
  addDrawOptions(*cmd, a->draw);
  cmd->add_option("--order", a->order, "Vertex order: original, morton, shuffled, shuffled-morton")
      ->capture_default_str();
  cmd->add_option("--points", a->points, "Points of a generated scene (e.g. 1M, 100M)")
      ->capture_default_str();
  cmd->add_option("--seed", a->seed, "Seed for generated scenes and shuffled orders")->capture_default_str();
  cmd->add_flag(
      "--events", a->events,
      "Print one JSON object a line on stdout: listening (with the URL and the process id), clients, "
      "refusals, the exit");
  cmd->add_option("--device", a->device, "Vulkan device index (see `pointrast info --devices`)");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress lines");
  return [a] { return runServe(*a); };
}

} // namespace pointrast::app
