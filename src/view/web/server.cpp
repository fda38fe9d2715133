#include "view/web/server.h"

#include <arpa/inet.h>
#include <csignal>
#include <pthread.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "cloud/cloud.h"
#include "gpu/context.h"
#include "view/web/access.h"
#include "view/web/civetweb_api.h"
#include "view/web/export.h"
#include "view/web/page.h"
#include "view/web/request_rules.h"

namespace pointrast::view::web {

namespace {

using Json = nlohmann::json;
namespace cw = civetweb;

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// WebSocket close codes (RFC 6455, 7.4.1).
constexpr uint16_t kCloseNormal = 1000;
constexpr uint16_t kCloseGoingAway = 1001;
constexpr uint16_t kClosePolicy = 1008;
constexpr uint16_t kCloseInternal = 1011;
constexpr uint16_t kCloseTryAgain = 1013;
// How long a shutdown waits for the clients' close frames to be written.
constexpr double kCloseGraceSeconds = 2.0;
// civetweb gives each connection a worker thread from the moment it is accepted, before a byte of the
// request arrives: connections that say nothing hold workers until the request timeout. The workers
// beyond the clients' let this many such connections be open while pages, /healthz and handshakes still
// find a free worker at once; the timeout (also the longest a write may make no progress) frees them.
constexpr uint32_t kIdleConnectionAllowance = 128;
constexpr const char* kRequestTimeoutMs = "3000";

// The headers of every answer: nothing cached, nothing framed, no referrer (the token may be in the URL),
// and scripts, styles and connections only from this server.
constexpr const char* kSecurityHeaders =
    "Cache-Control: no-store\r\n"
    "X-Content-Type-Options: nosniff\r\n"
    "X-Frame-Options: DENY\r\n"
    "Referrer-Policy: no-referrer\r\n"
    "Content-Security-Policy: default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' "
    "blob: data:; connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'\r\n";

// The viewer's own files carry the same headers, except that --frame-ancestors may name pages that embed it
// in a frame (a notebook's output cell).
std::string pageHeaders(const std::string& frameAncestors) {
  std::string headers = kSecurityHeaders;
  if (frameAncestors.empty()) return headers;
  headers.erase(headers.find("X-Frame-Options"), std::strlen("X-Frame-Options: DENY\r\n"));
  const std::string none = "frame-ancestors 'none'";
  headers.replace(headers.find(none), none.size(), "frame-ancestors " + frameAncestors);
  return headers;
}

void sendClose(mg_connection* conn, uint16_t code, std::string_view reason) {
  char payload[125]; // a control frame's payload is at most 125 bytes
  payload[0] = char(code >> 8);
  payload[1] = char(code & 0xFF);
  size_t n = std::min(reason.size(), sizeof payload - 2);
  std::memcpy(payload + 2, reason.data(), n);
  cw::mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE, payload, n + 2);
}

// One browser tab's connection, shared by civetweb's thread for it (input), the client's sender thread
// (output) and the render thread (its WebClient). Only the render thread destroys it, after the close.
struct Connection : MessageSink {
  uint64_t id = 0;
  mg_connection* conn = nullptr;
  bool refused = false; // over --max-clients: told so, then closed
  std::unique_ptr<FrameStream> stream;
  std::mutex inboxMutex;
  std::vector<ClientMessage> inbox;
  MessageBudget budget;  // civetweb's thread only
  Viewport canvas{0, 0}; // civetweb's thread only: the frame size its last resize asked for, clamped
  uint32_t supersample = 1;
  std::atomic<bool> ready{false}, closed{false};
  // The server has sent its close (a refused message, the closing handshake): the connection no longer
  // holds one of --max-clients' slots, though civetweb has yet to tear it down.
  std::atomic<bool> ending{false};

  bool sendText(std::string_view text) override {
    return cw::mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_TEXT, text.data(), text.size()) > 0;
  }
  bool sendBinary(std::span<const uint8_t> bytes) override {
    return cw::mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_BINARY,
                                  reinterpret_cast<const char*>(bytes.data()), bytes.size()) > 0;
  }
  void sendClose(uint16_t code, std::string_view reason) override { web::sendClose(conn, code, reason); }
};

// Lines on stderr about refused requests and clients, at most a few a second whatever a client sends.
class RateLimitedLog {
public:
  void line(const std::string& text) {
    std::lock_guard lock(mutex_);
    double t = now();
    if (t - windowStart_ >= 1.0) {
      if (suppressed_ > 0)
        std::fprintf(stderr, "pointrast serve: (%llu more like it)\n", (unsigned long long)suppressed_);
      windowStart_ = t;
      count_ = 0;
      suppressed_ = 0;
    }
    if (count_++ < kPerSecond)
      std::fprintf(stderr, "pointrast serve: %s\n", text.c_str());
    else
      suppressed_++;
  }

private:
  static constexpr uint32_t kPerSecond = 5;
  std::mutex mutex_;
  double windowStart_ = 0;
  uint32_t count_ = 0;
  uint64_t suppressed_ = 0;
};

class Server {
public:
  Server(SceneInput& input, const ServerOptions& options);
  ~Server();
  int run();

private:
  // civetweb's callbacks, each on one of its worker threads.
  static Server& of(const mg_connection* conn);
  static int beginRequest(mg_connection* conn);
  int serveExport(mg_connection* conn, const std::string& query);
  int serveProfile(mg_connection* conn, const std::string& path, const std::string& query);
  int sendDownload(mg_connection* conn, const std::filesystem::path& file, const std::string& name,
                   const char* type, uint64_t points);
  int refuseDownload(mg_connection* conn, int status, const std::string& why);
  static int logMessage(const mg_connection* conn, const char* message);
  static int httpError(mg_connection* conn, int status, const char* message);
  static int handleHttp(mg_connection* conn, void* self);
  static int wsConnect(const mg_connection* conn, void* self);
  static void wsReady(mg_connection* conn, void* self);
  static int wsData(mg_connection* conn, int bits, char* data, size_t length, void* self);
  static void wsClose(const mg_connection* conn, void* self);

  int gate(mg_connection* conn);
  int serveHttp(mg_connection* conn);
  int refuseMessage(Connection& c, uint16_t code, const std::string& why);
  bool boundSamples(Connection& c, ClientMessage& m);
  int receive(Connection& c, int bits, const char* data, size_t length);

  void start();
  void renderLoop();
  std::optional<double> renderPass();
  void wakeRenderer();
  void waitForCloses(double deadline);
  void emit(const Json& event);
  std::string url() const;

  SceneInput& input_;
  ServerOptions options_;
  AccessPolicy access_;
  std::string pageHeaders_; // security headers of the viewer's own files
  gpu::Context context_;
  std::unique_ptr<SceneSource> source_;
  std::vector<Method> methods_;
  ClientSetup setup_;
  std::string info_;
  mg_context* civet_ = nullptr;
  uint16_t port_ = 0;
  std::atomic<bool> stopping_{false};
  RateLimitedLog log_;
  std::mutex eventMutex_;

  std::mutex connectionsMutex_;
  std::map<uint64_t, std::unique_ptr<Connection>> connections_;
  uint64_t nextId_ = 1;

  std::mutex wakeMutex_;
  std::condition_variable wake_;
  bool work_ = false;
  std::thread renderThread_;
  std::map<uint64_t, std::unique_ptr<WebClient>> clients_; // render thread only
  std::exception_ptr renderError_;
  std::atomic<bool> renderFailed_{false};
  uint64_t framesServed_ = 0;
};

gpu::Context makeContext(const ServerOptions& options) {
  gpu::ContextOptions o;
  o.deviceIndex = options.device;
  o.announce = !options.quiet && options.announceDevice;
  return gpu::Context(o);
}

std::unique_ptr<SceneSource> makeSource(gpu::Context& context, SceneInput& input,
                                        const ServerOptions& options) {
  if (options.makeSource) return options.makeSource(context, input, options.settings);
  return makeSceneSource(context, input, options.settings, !options.quiet);
}

Server::Server(SceneInput& input, const ServerOptions& options)
    : input_(input), options_(options), context_(makeContext(options)),
      source_(makeSource(context_, input, options)) {
  access_.token = options.token;
  pageHeaders_ = pageHeaders(options.frameAncestors);
  // A client's page offers the methods that draw what was opened (an uploaded cloud, or an octree).
  methods_ = methodsFor(*source_, context_);
  ViewSettings settings = options.settings;
  settings.method = options.method ? *options.method : defaultMethod(*source_, context_);
  if (!source_->draws(settings.method)) throw InputError(notDrawn(*source_, settings.method));
  if (std::optional<std::string> why = source_->refuses(settings.method)) throw InputError(*why);
  if (std::find(methods_.begin(), methods_.end(), settings.method) == methods_.end())
    throw UnsupportedError(std::string("this device cannot run ") + methodName(settings.method));
  // The first client should not wait for the upload of the starting method's scene.
  if (auto* cloud = dynamic_cast<GpuCloud*>(source_.get())) cloud->scene(methodInfo(settings.method).layout);
  setup_.context = &context_;
  setup_.cloud = source_.get();
  setup_.methods = methods_;
  setup_.camera = options.camera;
  setup_.fovY = options.fovY;
  setup_.framing = input.framing;
  setup_.settings = settings;
  setup_.maxSize = options.maxSize;
  setup_.stream = options.stream;
  setup_.annotations = options.annotations;
  Json methods = Json::array();
  for (Method m : methods_)
    methods.push_back({{"name", methodName(m)}, {"help", methodInfo(m).help}});
  info_ = Json{{"t", "info"},
               {"device", context_.info().name},
               {"input", input.name},
               {"points", source_->pointCount()},
               {"methods", methods},
               {"maxSize", {options.maxSize.width, options.maxSize.height}},
               {"maxClients", options.maxClients},
               {"zoomPerStep", kZoomPerStep}}
              .dump();
}

Server::~Server() {
  if (civet_) cw::mg_stop(civet_);
}

Server& Server::of(const mg_connection* conn) {
  return *static_cast<Server*>(cw::mg_get_request_info(conn)->user_data);
}

void Server::emit(const Json& event) {
  if (!options_.events) return;
  std::lock_guard lock(eventMutex_);
  std::printf("%s\n", event.dump().c_str());
  std::fflush(stdout);
}

int Server::logMessage(const mg_connection* conn, const char* message) {
  if (conn) of(conn).log_.line(std::string("civetweb: ") + message);
  return 1; // handled: civetweb writes no log of its own
}

// civetweb's own error replies (a malformed request line, an unknown HTTP version, headers too long) would
// quote the request; ours carry only the status, so no byte of the request comes back (no header injected
// into the reply by a request holding line breaks).
int Server::httpError(mg_connection* conn, int status, const char*) {
  if (status < 400 || status > 599) return 1; // not an error: civetweb's own handling
  const char* text = status == 400   ? "Bad Request"
                     : status == 413 ? "Payload Too Large"
                     : status == 431 ? "Request Header Fields Too Large"
                     : status == 505 ? "HTTP Version Not Supported"
                     : status < 500  ? "Client Error"
                                     : "Server Error";
  std::string body = std::to_string(status) + " " + text + "\n";
  std::string head = "HTTP/1.1 " + std::to_string(status) + " " + text +
                     "\r\nContent-Type: text/plain; charset=utf-8\r\nConnection: close\r\n" +
                     kSecurityHeaders + "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n";
  cw::mg_write(conn, head.data(), head.size());
  cw::mg_write(conn, body.data(), body.size());
  return 0; // handled
}

// Every request, HTTP or WebSocket upgrade, passes here first: the access rules, and nothing but GET.
int Server::beginRequest(mg_connection* conn) {
  return of(conn).gate(conn);
}

int Server::gate(mg_connection* conn) {
  const mg_request_info* info = cw::mg_get_request_info(conn);
  auto header = [&](const char* name) {
    const char* v = cw::mg_get_header(conn, name);
    return std::string(v ? v : "");
  };
  // A token is compared by its decoded length: "%00" in it must not end the comparison early.
  char queryBuffer[128] = "", cookieBuffer[128] = "";
  int queryLength = -1, cookieLength = -1;
  if (info->query_string)
    queryLength = cw::mg_get_var(info->query_string, std::strlen(info->query_string), "token", queryBuffer,
                                 sizeof queryBuffer);
  std::string cookies = header("Cookie");
  if (!cookies.empty())
    cookieLength =
        cw::mg_get_cookie(cookies.c_str(), access_.cookieName().c_str(), cookieBuffer, sizeof cookieBuffer);
  std::string_view queryToken(queryBuffer, size_t(std::max(queryLength, 0)));
  std::string_view cookieToken(cookieBuffer, size_t(std::max(cookieLength, 0)));
  std::string authorization = header("Authorization"), bearer;
  if (authorization.rfind("Bearer ", 0) == 0) bearer = authorization.substr(7);
  std::string upgrade = header("Upgrade"), host = header("Host"), origin = header("Origin");
  HttpRequest request{info->request_method, info->local_uri ? info->local_uri : "",
                      RequestFacts{host, origin, queryToken, cookieToken, bearer, !upgrade.empty()}, false};
  // The page's script and style load without the token only when pages of other sites may frame the viewer
  // (--frame-ancestors: a notebook), whose requests carry no cookie there.
  request.publicPageFile = !options_.frameAncestors.empty() && isPublicPageFile(request.path);
  std::optional<HttpRefusal> refusal = gateRequest(access_, request, stopping_);
  if (!refusal) return 0; // on to the page or the WebSocket
  int status = refusal->status;
  std::string body = refusal->why;
  if (status == 403) {
    log_.line(std::string("refused ") + info->remote_addr + ": " + body);
    emit({{"event", "refused"}, {"why", body}, {"websocket", request.facts.websocket}});
  }
  body += "\n";
  const char* text = status == 400   ? "Bad Request"
                     : status == 403 ? "Forbidden"
                     : status == 405 ? "Method Not Allowed"
                                     : "Service Unavailable";
  std::string head = "HTTP/1.1 " + std::to_string(status) + " " + text +
                     "\r\nContent-Type: text/plain; charset=utf-8\r\nConnection: close\r\n" +
                     kSecurityHeaders + "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n";
  cw::mg_write(conn, head.data(), head.size());
  cw::mg_write(conn, body.data(), body.size());
  return status;
}

// A download's failure: the status and the one sentence why, which the page shows.
int Server::refuseDownload(mg_connection* conn, int status, const std::string& why) {
  const std::string body = why + "\n";
  const std::string head = "HTTP/1.1 " + std::to_string(status) +
                           (status == 400 ? " Bad Request" : " Internal Server Error") +
                           "\r\nContent-Type: text/plain; charset=utf-8\r\n" + pageHeaders_ +
                           "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n";
  cw::mg_write(conn, head.data(), head.size());
  cw::mg_write(conn, body.data(), body.size());
  return status;
}

// A written file streamed as the reply, with its point count in X-Points.
int Server::sendDownload(mg_connection* conn, const std::filesystem::path& file, const std::string& name,
                         const char* type, uint64_t points) {
  std::ifstream in(file, std::ios::binary);
  const uint64_t size = std::filesystem::file_size(file);
  const std::string head = "HTTP/1.1 200 OK\r\nContent-Type: " + std::string(type) +
                           "\r\nContent-Disposition: attachment; filename=\"" + name + "\"\r\n" +
                           pageHeaders_ + "X-Points: " + std::to_string(points) +
                           "\r\nContent-Length: " + std::to_string(size) + "\r\n\r\n";
  cw::mg_write(conn, head.data(), head.size());
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    if (in.gcount() > 0 && cw::mg_write(conn, buffer.data(), size_t(in.gcount())) <= 0) break;
  }
  return 200;
}

// The points inside the page's clip box as LAS (export.h), or 400 with the one sentence why not.
int Server::serveExport(mg_connection* conn, const std::string& query) {
  const ExportSource source = exportSource(options_.inputFile);
  if (!source.file) return refuseDownload(conn, 400, "export: " + source.whyNot);
  try {
    const PointFilter filter = parseExportQuery(query);
    uint64_t points = 0;
    exportLas(*source.file, filter, [&](const std::filesystem::path& file, uint64_t count) {
      points = count;
      sendDownload(conn, file, "export.las", "application/octet-stream", count);
    });
    emit({{"event", "export"}, {"points", points}});
    return 200;
  } catch (const InputError& e) {
    return refuseDownload(conn, 400, e.what());
  }
}

// The profile along the page's line (export.h): /profile.png, /profile.las or /profile.csv, cut on this
// worker thread (it reads the input from disk), not on the render thread every page shares.
int Server::serveProfile(mg_connection* conn, const std::string& path, const std::string& query) {
  const ProfileOutput output = path == "/profile.png"   ? ProfileOutput::Png
                               : path == "/profile.las" ? ProfileOutput::Las
                                                        : ProfileOutput::Csv;
  const char* type = output == ProfileOutput::Png   ? "image/png"
                     : output == ProfileOutput::Las ? "application/octet-stream"
                                                    : "text/csv; charset=utf-8";
  try {
    const ProfileQuery q = parseProfileQuery(query, output);
    const uint64_t points =
        exportProfile(options_.inputFile, q, output, [&](const std::filesystem::path& file, uint64_t count) {
          sendDownload(conn, file, file.filename().string(), type, count);
        });
    emit({{"event", "profile"}, {"output", path.substr(9)}, {"points", points}});
    return 200;
  } catch (const InputError& e) {
    return refuseDownload(conn, 400, e.what());
  } catch (const std::exception& e) {
    return refuseDownload(conn, 500, std::string("profile: ") + e.what());
  }
}

int Server::handleHttp(mg_connection* conn, void* self) {
  return static_cast<Server*>(self)->serveHttp(conn);
}

int Server::serveHttp(mg_connection* conn) {
  const mg_request_info* info = cw::mg_get_request_info(conn);
  // civetweb leaves the path as sent ("decode_url" off): decoded here, where a "%00" is seen, not cut at.
  std::string path = decodePath(info->local_uri ? info->local_uri : "").value_or("");
  std::string_view type = "text/plain; charset=utf-8", body;
  int status = 200;
  std::string extra;
  if (path == "/healthz") {
    body = "ok\n";
  } else if (path == "/export.las") {
    return serveExport(conn, info->query_string ? info->query_string : "");
  } else if (path == "/profile.png" || path == "/profile.las" || path == "/profile.csv") {
    return serveProfile(conn, path, info->query_string ? info->query_string : "");
  } else if (const PageFile* file = findPageFile(path)) {
    type = file->contentType;
    body = file->body;
    // The page's later requests (script, style, WebSocket) carry the token in a cookie: the address bar
    // can drop it. Strict: no other site's page sends it along.
    char token[128] = "";
    int length = info->query_string ? cw::mg_get_var(info->query_string, std::strlen(info->query_string),
                                                     "token", token, sizeof token)
                                    : -1;
    if (!access_.token.empty() && length > 0 && tokenMatches({token, size_t(length)}, access_.token))
      extra = "Set-Cookie: " + access_.cookieName() + "=" + access_.token + "; HttpOnly; SameSite=Strict\r\n";
  } else {
    status = 404;
    body = "not found: this server serves its viewer page only\n";
  }
  std::string head = "HTTP/1.1 " + std::to_string(status) + (status == 200 ? " OK" : " Not Found") +
                     "\r\nContent-Type: " + std::string(type) + "\r\n" + pageHeaders_ + extra +
                     "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n";
  cw::mg_write(conn, head.data(), head.size());
  if (std::strcmp(info->request_method, "HEAD") != 0) cw::mg_write(conn, body.data(), body.size());
  return status;
}

int Server::wsConnect(const mg_connection* conn, void* selfPointer) {
  Server& self = *static_cast<Server*>(selfPointer);
  auto c = std::make_unique<Connection>();
  std::lock_guard lock(self.connectionsMutex_);
  size_t open = 0;
  for (const auto& [id, other] : self.connections_)
    open += other->closed || other->refused || other->ending ? 0 : 1; // those on their way out are not
  c->refused = open >= self.options_.maxClients;
  c->id = self.nextId_++;
  cw::mg_set_user_connection_data(conn, c.get());
  self.connections_[c->id] = std::move(c);
  return 0;
}

void Server::wsReady(mg_connection* conn, void* selfPointer) {
  Server& self = *static_cast<Server*>(selfPointer);
  auto& c = *static_cast<Connection*>(cw::mg_get_user_connection_data(conn));
  c.conn = conn;
  if (c.refused) {
    // One close frame whose reason the page shows: a browser reads the reason of a close after the
    // handshake, never the body of a refused upgrade.
    std::string why = "server full: " + std::to_string(self.options_.maxClients) +
                      " clients (--max-clients); try again later";
    sendClose(conn, kCloseTryAgain, why);
    self.emit({{"event", "refused"}, {"why", why}, {"websocket", true}});
    return;
  }
  c.stream = std::make_unique<FrameStream>(c, [&self] { self.wakeRenderer(); });
  c.stream->submitText(self.info_);
  c.ready = true;
  self.emit({{"event", "client"}, {"id", c.id}, {"state", "open"}});
  self.wakeRenderer();
}

// What one client may make the server hold scales with its frame's samples (size x supersample^2): the
// renderers, the screenshot's readback and its PNG. A supersample that would pass kMaxClientSamples is
// refused with a message (the client stays); a resize under a supersample lowers the supersample first.
bool Server::boundSamples(Connection& c, ClientMessage& m) {
  auto samples = [](Viewport v, uint32_t s) { return uint64_t(v.width) * v.height * s * s; };
  auto largestSupersample = [&](Viewport v) {
    uint32_t s = 4;
    while (s > 1 && samples(v, s) > kMaxClientSamples)
      s /= 2;
    return s;
  };
  if (m.type == MessageType::Resize) {
    c.canvas = clampViewport(m.width, m.height, options_.maxSize);
    uint32_t s = largestSupersample(c.canvas);
    if (s < c.supersample) {
      c.supersample = s;
      ClientMessage lower;
      lower.type = MessageType::Options;
      lower.supersample = s;
      lower.received = now();
      std::lock_guard lock(c.inboxMutex);
      c.inbox.push_back(std::move(lower)); // before the resize that needs it
    }
    return true;
  }
  if (m.type != MessageType::Options || !m.supersample) return true;
  if (samples(c.canvas, *m.supersample) > kMaxClientSamples) {
    std::string why = "supersample " + std::to_string(*m.supersample) + " at " +
                      std::to_string(c.canvas.width) + "x" + std::to_string(c.canvas.height) +
                      " would pass the server's " + std::to_string(kMaxClientSamples) +
                      " samples per client; supersample " + std::to_string(largestSupersample(c.canvas)) +
                      " is the most at this size";
    c.stream->submitText(Json{{"t", "error"}, {"message", why}}.dump());
    m.supersample.reset();
    return m.keyframeSeconds.has_value();
  }
  c.supersample = *m.supersample;
  return true;
}

int Server::refuseMessage(Connection& c, uint16_t code, const std::string& why) {
  log_.line("client " + std::to_string(c.id) + " cut off: " + why);
  emit({{"event", "refused"}, {"id", c.id}, {"why", why}, {"websocket", true}});
  c.ending = true;
  sendClose(c.conn, code, why.substr(0, 100));
  return 0; // civetweb closes the connection
}

int Server::wsData(mg_connection* conn, int bits, char* data, size_t length, void* self) {
  auto& c = *static_cast<Connection*>(cw::mg_get_user_connection_data(conn));
  return static_cast<Server*>(self)->receive(c, bits, data, length);
}

// The frame rules of RFC 6455 (request_rules.h) on what civetweb passes on; civetweb answers pings and
// drops pongs itself, and does not tell this handler whether a frame was masked.
int Server::receive(Connection& c, int bits, const char* data, size_t length) {
  std::string_view payload(data, length);
  FrameVerdict frame = checkFrame(bits, payload);
  if (frame.action == FrameAction::Refuse) return refuseMessage(c, frame.code, frame.why);
  if (frame.action == FrameAction::Ignore) return 1;
  if (frame.action == FrameAction::Close) {
    // The closing handshake's answer, after the last frame the sender was writing; none when this server
    // closed first (the client's frame is then the answer).
    c.ending = true;
    if (!c.refused && !stopping_) {
      if (c.stream) c.stream->stop();
      sendClose(c.conn, kCloseNormal, "");
    }
    return 0;
  }
  if (c.refused || !c.ready) return 0;
  if (!c.budget.take(now()))
    return refuseMessage(c, kClosePolicy, "more than the allowed messages per second");
  if (auto refused = checkMessage(bits, payload, kMaxMessageBytes))
    return refuseMessage(c, refused->code, refused->why);
  auto parsed = parseClientMessage({data, length}, methods_);
  if (auto* why = std::get_if<std::string>(&parsed))
    return refuseMessage(c, kClosePolicy, "invalid message: " + *why);
  ClientMessage& m = std::get<ClientMessage>(parsed);
  if (!boundSamples(c, m)) return 1;
  if (m.type == MessageType::Ack) {
    if (!c.stream->acknowledge(m.frame))
      return refuseMessage(c, kClosePolicy, "acknowledged a frame not sent");
    return 1;
  }
  m.received = now();
  {
    std::lock_guard lock(c.inboxMutex);
    // The budget bounds this: at most a burst of messages waits for the render thread.
    c.inbox.push_back(std::move(m));
  }
  wakeRenderer();
  return 1;
}

void Server::wsClose(const mg_connection* conn, void* selfPointer) {
  Server& self = *static_cast<Server*>(selfPointer);
  auto* c = static_cast<Connection*>(cw::mg_get_user_connection_data(conn));
  if (!c) return;
  // The sender finishes the write it is in; no write happens after this returns and civetweb frees conn.
  if (c->stream) c->stream->stop();
  c->closed = true;
  if (!c->refused) self.emit({{"event", "client"}, {"id", c->id}, {"state", "closed"}});
  self.wakeRenderer();
}

void Server::wakeRenderer() {
  std::lock_guard lock(wakeMutex_);
  work_ = true;
  wake_.notify_one();
}

// One pass over the clients: new ones get a WebClient, closed ones lose theirs (GPU objects are freed on
// this thread), the others take their input and render if due. Returns when to come back unasked.
std::optional<double> Server::renderPass() {
  std::vector<std::pair<Connection*, WebClient*>> active;
  {
    std::lock_guard lock(connectionsMutex_);
    for (auto it = connections_.begin(); it != connections_.end();) {
      Connection& c = *it->second;
      if (c.closed) {
        clients_.erase(c.id);
        it = connections_.erase(it);
        continue;
      }
      if (c.ready && !clients_.count(c.id)) clients_[c.id] = std::make_unique<WebClient>(setup_, *c.stream);
      if (c.ready) active.emplace_back(&c, clients_[c.id].get());
      ++it;
    }
  }
  std::optional<double> next;
  for (auto [c, client] : active) {
    std::vector<ClientMessage> inbox;
    {
      std::lock_guard lock(c->inboxMutex);
      inbox.swap(c->inbox);
    }
    try {
      for (const ClientMessage& m : inbox)
        client->receive(m);
      std::optional<double> when = client->step(now());
      if (when && (!next || *when < *next)) next = when;
    } catch (const InputError& e) { // e.g. a canvas larger than the device can hold a renderer for
      c->stream->submitText(Json{{"t", "error"}, {"message", e.what()}}.dump());
      c->stream->submitClose(kClosePolicy, "cannot render this client's frames");
    } catch (const UnsupportedError& e) {
      c->stream->submitText(Json{{"t", "error"}, {"message", e.what()}}.dump());
      c->stream->submitClose(kClosePolicy, "cannot render this client's frames");
    }
  }
  return next;
}

void Server::renderLoop() {
  try {
    while (!stopping_) {
      std::optional<double> next = renderPass();
      std::unique_lock lock(wakeMutex_);
      auto ready = [&] { return work_ || stopping_; };
      if (next)
        wake_.wait_for(lock, std::chrono::duration<double>(std::max(0.0, *next - now())), ready);
      else
        wake_.wait(lock, ready);
      work_ = false;
    }
  } catch (...) {
    // A lost device (or any other failure of the render thread) ends the server: every page is told why
    // before run() closes the connections and the error becomes the process's one line on stderr.
    renderError_ = std::current_exception();
    std::string why = "the server stopped rendering";
    try {
      throw;
    } catch (const std::exception& e) {
      why = std::string("the server stopped: ") + e.what();
    } catch (...) {
    }
    {
      std::lock_guard lock(connectionsMutex_);
      for (auto& [id, c] : connections_)
        if (c->stream) c->stream->submitText(Json{{"t", "error"}, {"message", why}}.dump());
    }
    renderFailed_ = true;
    kill(getpid(), SIGTERM); // wakes run()'s sigwait
  }
  // The GPU objects of every client go on this thread, before the context.
  clients_.clear();
}

// The senders put their close frames on the wire before mg_stop ends the connections under them; one that
// a stalled client blocks is given up at the deadline.
void Server::waitForCloses(double deadline) {
  while (now() < deadline) {
    bool sent = true;
    {
      std::lock_guard lock(connectionsMutex_);
      for (const auto& [id, c] : connections_)
        sent = sent && (!c->stream || c->stream->stopped());
    }
    if (sent) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

std::string Server::url() const {
  std::string host = options_.bind;
  if (host == "0.0.0.0" || host == "::") {
    char name[256] = "";
    if (gethostname(name, sizeof name - 1) == 0 && name[0]) host = name;
  } else if (host.find(':') != std::string::npos) {
    host = "[" + host + "]";
  }
  std::string u = "http://" + host + ":" + std::to_string(port_) + "/";
  if (!access_.token.empty()) u += "?token=" + access_.token;
  return u;
}

void Server::start() {
  cw::mg_init_library(MG_FEATURES_WEBSOCKET);
  std::string address = options_.bind == "localhost" ? "127.0.0.1" : options_.bind;
  std::string ports = (address.find(':') != std::string::npos ? "[" + address + "]" : address) + ":" +
                      std::to_string(options_.port);
  // Each WebSocket holds a worker thread for its life: the clients, plus some for page loads and refusals,
  // plus the idle connections' allowance.
  std::string threads = std::to_string(options_.maxClients + 4 + kIdleConnectionAllowance);
  const char* civetOptions[] = {"listening_ports",
                                ports.c_str(),
                                "num_threads",
                                threads.c_str(),
                                "request_timeout_ms",
                                kRequestTimeoutMs,
                                "websocket_timeout_ms",
                                "30000",
                                "enable_websocket_ping_pong",
                                "yes",
                                "enable_keep_alive",
                                "yes",
                                "decode_url",
                                "no",
                                // Frames and their small state messages go out at once: with Nagle's
                                // algorithm a message waits for the peer's delayed acknowledgement
                                // (up to 40 ms on Linux) while a frame is on its way.
                                "tcp_nodelay",
                                "1",
                                nullptr};
  mg_callbacks callbacks{};
  callbacks.begin_request = &Server::beginRequest;
  callbacks.log_message = &Server::logMessage;
  callbacks.http_error = &Server::httpError;
  civet_ = cw::mg_start(&callbacks, this, civetOptions);
  if (!civet_)
    throw InputError("cannot listen on " + ports +
                     " (the port is in use, or the address is not this machine's)");
  cw::mg_set_request_handler(civet_, "/", &Server::handleHttp, this);
  cw::mg_set_websocket_handler(civet_, "/ws", &Server::wsConnect, &Server::wsReady, &Server::wsData,
                               &Server::wsClose, this);
  mg_server_port bound[4]{};
  int n = cw::mg_get_server_ports(civet_, 4, bound);
  port_ = n > 0 ? uint16_t(bound[0].port) : options_.port;
  access_.port = port_;
}

sigset_t stopSignals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  return signals;
}

int Server::run() {
  sigset_t signals = stopSignals();
  start();
  renderThread_ = std::thread([this] { renderLoop(); });
  std::string link = url();
  emit({{"event", "listening"}, {"url", link}, {"port", port_}, {"bind", options_.bind}, {"pid", getpid()}});
  if (!options_.events && !options_.quiet)
    std::printf("pointrast serve: %s  (%s, %s points; Ctrl-C stops)\n", link.c_str(), input_.name.c_str(),
                humanCount(double(input_.points)).c_str());
  std::fflush(stdout);
  int signal = 0;
  sigwait(&signals, &signal);

  stopping_ = true;
  {
    std::lock_guard lock(connectionsMutex_);
    for (auto& [id, c] : connections_)
      if (c->stream)
        c->stream->submitClose(renderFailed_ ? kCloseInternal : kCloseGoingAway,
                               renderFailed_ ? "server error" : "server shutting down");
  }
  wakeRenderer();
  renderThread_.join();
  waitForCloses(now() + kCloseGraceSeconds);
  cw::mg_stop(civet_); // waits for civetweb's threads; the close handlers stop the remaining senders
  civet_ = nullptr;
  connections_.clear();
  if (renderError_) {
    emit({{"event", "exit"}, {"signal", signal}, {"error", true}});
    std::rethrow_exception(renderError_);
  }
  uint32_t errors = context_.validationErrors();
  emit({{"event", "exit"}, {"signal", signal}, {"validation_errors", errors}});
  if (errors > 0) {
    std::fprintf(stderr, "pointrast: the Vulkan validation layer reported %u error(s)\n", errors);
    return 1;
  }
  return 0;
}

} // namespace

void checkServerOptions(const ServerOptions& o) {
  in6_addr v6{};
  in_addr v4{};
  if (o.bind != "localhost" && inet_pton(AF_INET, o.bind.c_str(), &v4) != 1 &&
      inet_pton(AF_INET6, o.bind.c_str(), &v6) != 1)
    throw InputError("--bind " + o.bind + ": give an IP address of this machine (or localhost)");
  if (o.maxClients == 0) throw InputError("--max-clients must be at least 1");
  if (o.maxClients > 64)
    throw InputError("--max-clients takes at most 64 (each client has its own renderer)");
  if (o.maxSize.width == 0 || o.maxSize.height == 0 || o.maxSize.width > kMaxCanvasSide ||
      o.maxSize.height > kMaxCanvasSide)
    throw InputError("--max-size takes WxH with sides from 1 to " + std::to_string(kMaxCanvasSide));
  if (!o.token.empty() &&
      (o.token.size() < 16 || o.token.size() > 100 ||
       o.token.find_first_not_of("0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ-_") !=
           std::string::npos))
    throw InputError("--token takes 16 to 100 letters, digits, '-' or '_'");
  // Sources as a Content-Security-Policy writes them ("http://localhost:*", "'self'"): nothing that could end
  // the header or the directive.
  if (o.frameAncestors.size() > 512 ||
      o.frameAncestors.find_first_not_of("0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                         "-_.:/*' ") != std::string::npos)
    throw InputError("--frame-ancestors takes page origins such as http://localhost:* separated by spaces");
}

int runServer(SceneInput& input, ServerOptions options) {
  checkServerOptions(options);
  if (input.points == 0) throw InputError(input.name + ": no points to view");
  cw::load();
  if (options.token.empty() && !isLocalBind(options.bind)) options.token = generateToken();
  // SIGINT and SIGTERM are taken by sigwait in Server::run, never by a handler on some thread: blocked
  // before any thread starts (the Vulkan driver's, civetweb's, ours), every thread inherits the mask.
  sigset_t signals = stopSignals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
  Server server(input, options);
  return server.run();
}

} // namespace pointrast::view::web
