// `pointrast serve`: the browser viewer. One civetweb server on one port serves the embedded page and a
// WebSocket per browser tab; one render thread owns the GPU (one scene shared by every client, a renderer
// per client) and hands frames to each client's sender thread, which encodes JPEG and writes. Runs until
// SIGINT or SIGTERM, then closes every client and stops cleanly.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "view/web/client.h"

namespace pointrast {
struct PointCloud;
}

namespace pointrast::view::web {

// Frames larger than this per side are not rendered unless --max-size says so.
constexpr Viewport kDefaultMaxSize{3840, 2160};
constexpr uint32_t kDefaultMaxClients = 4;
// The most samples (frame width x height x supersample^2) one client may have drawn: 3840x2160 at
// supersample 1, 1920x1080 at 2, 960x540 at 4. A client's renderers and screenshot scale with it.
constexpr uint64_t kMaxClientSamples = 3840ull * 2160;

struct ServerOptions {
  std::string bind = "127.0.0.1"; // an IP address or localhost
  uint16_t port = 8080;           // 0: any free port (printed)
  std::string token;              // required from clients when not empty; generated for a non-local bind
  uint32_t maxClients = kDefaultMaxClients;
  std::optional<Camera> camera; // every client's starting camera; the overview when absent
  double fovY = 60;
  ViewSettings settings;        // settings.method is ignored: `method` below chooses
  std::optional<Method> method; // absent: defaultMethod() for the input and the device
  Viewport maxSize = kDefaultMaxSize;
  StreamSettings stream;
  Annotations annotations; // --annotations: every page's measurement list starts with them
  std::string inputFile;   // the file the input was read from (empty: a generated scene), for /export.las
  std::optional<uint32_t> device;
  std::string frameAncestors; // pages that may show the viewer in a frame (CSP sources); empty: none
  bool events = false; // one JSON object a line on stdout: listening, clients, refusals, the exit
  bool quiet = false;
  bool announceDevice = true; // the device's line on stderr (unless quiet)
  // How the input goes on the device (default: makeSceneSource); a distributed viewer's rank 0 draws
  // every rank's share through it (docs/mpi.md).
  std::function<std::unique_ptr<SceneSource>(gpu::Context&, SceneInput&, const ViewSettings&)> makeSource;
};

// InputError with one sentence for options that cannot work; runServer checks them too. Callers check before
// loading a large cloud.
void checkServerOptions(const ServerOptions& options);

// Checks the options (InputError with one sentence), generates the token a non-local bind needs, and
// serves until a signal. Returns the exit code: 1 when the validation layer reported errors.
int runServer(SceneInput& input, ServerOptions options);

} // namespace pointrast::view::web
