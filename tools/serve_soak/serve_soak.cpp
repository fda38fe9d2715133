// serve_soak: keeps `pointrast serve` busy with clients that come and go for a while and says whether it
// stayed well: it starts the server (the command after `--`, given --port 0 --events -q), and until
// --seconds have passed runs
//   - viewers that behave (a canvas, drags and wheel steps at --rate, every frame acknowledged), each
//     session some seconds long, then a new connection;
//   - clients that vanish in the middle of a frame, slow readers that stop reading while they move,
//     clients that send malformed messages, idle sockets that say nothing, and page and health requests;
// samples the server's resident memory and open descriptors (/proc/PID/status, /proc/PID/fd) every
// --sample seconds, counts frames, error messages and refusals, stops the server with SIGTERM and writes
// a JSON report and a Markdown table. It exits 1 when the server died, its memory grew more than
// --rss-growth-mb after the warm-up, it holds more descriptors once its clients are gone than before the
// first came (beyond --fd-slack), a well-behaved client was refused or cut off without a reason, or an
// error message given by --expect-page-error never reached a page.
//
//   serve_soak --seconds 60 [--sample 2] [--warmup 10] [--viewers 2] [--rate 30] [--rss-growth-mb 256]
//              [--fd-slack 8] [--expect-page-error TEXT] [-o soak.json] [--markdown soak.md]
//              -- pointrast serve terrain --points 1M
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <netinet/in.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "view/web/protocol.h"
#include "ws_client.h"

namespace {

using Json = nlohmann::json;
using namespace pointrast;
using Clock = std::chrono::steady_clock;

struct Args {
  double seconds = 60, sample = 2, warmup = 10, rate = 30, rssGrowthMb = 256;
  int viewers = 2, fdSlack = 8;
  std::string expectPageError, json, markdown;
  std::vector<std::string> command;
};

struct Sample {
  double t = 0, rssMb = 0;
  int fds = 0, clients = 0;
  uint64_t frames = 0;
};

// What the clients saw, shared by their threads.
struct Tally {
  std::atomic<uint64_t> frames{0}, viewerSessions{0}, vanished{0}, slowSessions{0}, badSessions{0},
      badCutOff{0}, idleSockets{0}, httpRequests{0};
  std::mutex mutex;
  std::map<std::string, int> pageErrors; // error messages a page was sent, by text
  std::vector<std::string> failures;     // what a well-behaved client met that it should not have
  void fail(const std::string& what) {
    std::lock_guard lock(mutex);
    if (failures.size() < 50) failures.push_back(what);
  }
  void pageError(const std::string& what) {
    std::lock_guard lock(mutex);
    ++pageErrors[what.substr(0, 300)];
  }
};

double seconds(Clock::time_point from) {
  return std::chrono::duration<double>(Clock::now() - from).count();
}

// The server as a child process, its events read from its stdout.
class Server {
public:
  bool start(const std::vector<std::string>& command) {
    int fds[2];
    if (pipe(fds) != 0) return false;
    pid_ = fork();
    if (pid_ == 0) {
      prctl(PR_SET_PDEATHSIG, SIGTERM); // the server never outlives the soak, even one that was killed
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      close(fds[1]);
      std::vector<std::string> args = command;
      for (const char* a : {"--port", "0", "--events", "-q"})
        args.push_back(a);
      std::vector<char*> argv;
      for (std::string& a : args)
        argv.push_back(a.data());
      argv.push_back(nullptr);
      execvp(argv[0], argv.data());
      std::fprintf(stderr, "serve_soak: cannot run %s: %s\n", argv[0], std::strerror(errno));
      _exit(127);
    }
    close(fds[1]);
    reader_ = std::thread([this, fd = fds[0]] { read(fd); });
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, std::chrono::seconds(600), [&] { return port_ != 0 || ended_; });
    return port_ != 0;
  }
  ~Server() {
    if (alive()) stop();
    if (reader_.joinable()) reader_.join();
  }
  pid_t pid() const { return pid_; }
  uint16_t port() const { return port_; }
  int openClients() {
    std::lock_guard lock(mutex_);
    return open_;
  }
  int refusals() {
    std::lock_guard lock(mutex_);
    return refusals_;
  }
  // Waits for no open client (the server saw every close), at most `limit` seconds.
  bool waitForNoClients(double limit) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, std::chrono::duration<double>(limit), [&] {
      return open_ == 0 || ended_;
    }) && open_ == 0;
  }
  bool alive() {
    if (pid_ <= 0 || status_ >= 0) return false;
    int s = 0;
    if (waitpid(pid_, &s, WNOHANG) != pid_) return true;
    status_ = s;
    return false;
  }
  // SIGTERM, then the exit code (128 + signal when killed; -1 when it did not stop within a minute).
  int stop() {
    if (alive()) {
      kill(pid_, SIGTERM);
      for (int i = 0; i < 600 && alive(); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      if (alive()) {
        kill(pid_, SIGKILL);
        waitpid(pid_, &status_, 0);
        return -1;
      }
    }
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : 128 + WTERMSIG(status_);
  }

private:
  void read(int fd) {
    std::string line;
    char buffer[4096];
    ssize_t n;
    while ((n = ::read(fd, buffer, sizeof buffer)) > 0)
      for (ssize_t i = 0; i < n; ++i) {
        if (buffer[i] != '\n') {
          line += buffer[i];
          continue;
        }
        Json e = Json::parse(line, nullptr, false);
        line.clear();
        if (!e.is_object()) continue;
        std::lock_guard lock(mutex_);
        std::string event = e.value("event", "");
        if (event == "listening") port_ = e.value("port", 0);
        if (event == "client") open_ += e.value("state", "") == "open" ? 1 : -1;
        if (event == "refused") ++refusals_;
        changed_.notify_all();
      }
    close(fd);
    std::lock_guard lock(mutex_);
    ended_ = true;
    changed_.notify_all();
  }

  pid_t pid_ = -1;
  int status_ = -1;
  std::thread reader_;
  std::mutex mutex_;
  std::condition_variable changed_;
  uint16_t port_ = 0;
  int open_ = 0, refusals_ = 0;
  bool ended_ = false;
};

Sample sampleProcess(pid_t pid) {
  Sample s;
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) s.rssMb = std::strtod(line.c_str() + 6, nullptr) / 1024.0;
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/fd", ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec))
    ++s.fds;
  return s;
}

// The page's text messages: errors and status lines are tallied. Returns false on a close (frame or
// connection).
bool takeText(const wsclient::Message& m, Tally& tally, bool& toldWhy) {
  if (m.opcode == 8) return false;
  if (m.opcode != 1) return true;
  Json j = Json::parse(m.text(), nullptr, false);
  if (j.is_object() && j.value("t", "") == "error") {
    tally.pageError(j.value("message", ""));
    toldWhy = true;
  }
  // A frame that could not be drawn (a damaged octree node) is said in the state's status line.
  if (j.is_object() && j.value("t", "") == "state" && j.contains("stats") && j["stats"].is_object() &&
      j["stats"].contains("status") && j["stats"]["status"].is_string())
    tally.pageError(j["stats"]["status"].get<std::string>());
  return true;
}

// A well-behaved viewer: sessions of 4 to 12 s, each a new connection with a canvas, drags and wheel steps
// at `rate`, every frame acknowledged. A refused connection, or one closed with no error message first, is
// a failure.
void viewer(int index, const Args& args, uint16_t port, const std::atomic<bool>& stop, Tally& tally) {
  std::mt19937 rng(1234u + unsigned(index));
  std::uniform_real_distribution<double> u(0, 1);
  while (!stop) {
    wsclient::Client ws;
    if (!ws.connect("127.0.0.1", port, "/ws")) {
      if (stop) return;
      tally.fail("viewer " + std::to_string(index) + " refused: HTTP " +
                 std::to_string(ws.response().status) + " " + ws.response().body.substr(0, 200));
      std::this_thread::sleep_for(std::chrono::seconds(1));
      continue;
    }
    ++tally.viewerSessions;
    ws.sendText(Json{{"t", "resize"}, {"w", 160}, {"h", 120}}.dump());
    auto start = Clock::now();
    double length = 4 + 8 * u(rng), step = 1.0 / args.rate;
    bool down = false, toldWhy = false, open = true;
    double x = 0.5, y = 0.5;
    int n = 0;
    double nextInput = 0;
    while (open && !stop && seconds(start) < length) {
      auto m = ws.receive(std::max(0.0, nextInput - seconds(start)));
      if (m && m->opcode == 2 && m->data.size() >= view::web::kFrameHeaderBytes) {
        auto h = view::web::readFrameHeader(m->data.data());
        ws.sendText(Json{{"t", "ack"}, {"frame", h.frame}}.dump());
        ++tally.frames;
      } else if (m) {
        open = takeText(*m, tally, toldWhy);
      } else if (!ws.open()) {
        open = false;
      }
      if (!open || seconds(start) < nextInput) continue;
      nextInput = seconds(start) + step;
      // One input per step: strokes across the view, now and then a wheel step in or out.
      ++n;
      if (n % 40 == 0) {
        ws.sendText(
            Json{{"t", "wheel"}, {"x", u(rng)}, {"y", u(rng)}, {"steps", u(rng) < 0.6 ? 2 : -2}}.dump());
      } else if (!down) {
        x = 0.3 + 0.4 * u(rng);
        y = 0.3 + 0.4 * u(rng);
        ws.sendText(Json{{"t", "down"}, {"b", u(rng) < 0.7 ? 0 : 2}, {"x", x}, {"y", y}}.dump());
        down = true;
      } else if (n % 20 == 0) {
        ws.sendText(Json{{"t", "up"}, {"b", 0}, {"x", x}, {"y", y}}.dump());
        ws.sendText(Json{{"t", "up"}, {"b", 2}, {"x", x}, {"y", y}}.dump());
        down = false;
      } else {
        x = std::clamp(x + 0.02 * (u(rng) - 0.3), 0.0, 1.0);
        y = std::clamp(y + 0.02 * (u(rng) - 0.5), 0.0, 1.0);
        ws.sendText(Json{{"t", "move"}, {"x", x}, {"y", y}}.dump());
      }
    }
    if (!open && !stop && !toldWhy)
      tally.fail("viewer " + std::to_string(index) + " cut off without an error message after " +
                 std::to_string(seconds(start)) + " s");
  }
}

// Clients that misbehave, one kind after another: gone in the middle of a frame, a slow reader that moves
// but does not read for 2 s, malformed messages (the server may cut those off), an idle socket, requests.
void misbehave(const std::atomic<bool>& stop, uint16_t port, Tally& tally) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(0, 1);
  for (int round = 0; !stop; ++round) {
    switch (round % 5) {
    case 0: {
      wsclient::Client ws;
      if (!ws.connect("127.0.0.1", port, "/ws")) break;
      ws.sendText(R"({"t":"resize","w":320,"h":240})");
      ws.receive(0.02 + 0.1 * u(rng)); // maybe part of a frame
      ws.close();
      ++tally.vanished;
      break;
    }
    case 1: {
      wsclient::Client ws;
      if (!ws.connect("127.0.0.1", port, "/ws")) break;
      ws.sendText(R"({"t":"resize","w":320,"h":240})");
      ws.sendText(R"({"t":"down","b":0,"x":0.5,"y":0.5})");
      auto start = Clock::now();
      for (int i = 0; seconds(start) < 2 && !stop; ++i) {
        ws.sendText(Json{{"t", "move"}, {"x", 0.5 + 0.1 * std::sin(i * 0.1)}, {"y", 0.5}}.dump());
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      ws.receive(0.5);
      ws.close();
      ++tally.slowSessions;
      break;
    }
    case 2: {
      wsclient::Client ws;
      if (!ws.connect("127.0.0.1", port, "/ws")) break;
      const char* bad[] = {"{",
                           "null",
                           R"({"t":"nothing"})",
                           R"({"t":"resize","w":-5,"h":1e99})",
                           R"({"t":"move","x":"a"})",
                           "\xff\xfe"};
      for (const char* b : bad)
        ws.sendText(b);
      std::vector<uint8_t> junk(64);
      for (uint8_t& v : junk)
        v = uint8_t(rng());
      ws.sendFrame(0x82, junk); // binary, which the page never sends
      ws.sendFrame(0x83, junk); // a reserved opcode: the server closes
      for (int i = 0; i < 20; ++i) {
        auto m = ws.receive(2);
        if (!m || m->opcode == 8) break;
      }
      if (!ws.open()) ++tally.badCutOff;
      ws.close();
      ++tally.badSessions;
      break;
    }
    case 3: {
      int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
      sockaddr_in a{};
      a.sin_family = AF_INET;
      a.sin_port = htons(port);
      a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      if (fd >= 0 && connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
        for (int i = 0; i < 20 && !stop; ++i)
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
        ++tally.idleSockets;
      }
      if (fd >= 0) close(fd);
      break;
    }
    case 4: {
      // A page load and a health check must always be answered.
      for (const char* target : {"/", "/healthz"}) {
        auto r = wsclient::httpRequest("127.0.0.1", port, target);
        ++tally.httpRequests;
        if (r.status != 200 && !stop)
          tally.fail(std::string("GET ") + target + " answered " + std::to_string(r.status));
      }
      break;
    }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

int usage(const char* why) {
  std::fprintf(
      stderr,
      "serve_soak: %s\nusage: serve_soak [--seconds S] [--sample S] [--warmup S] [--viewers N] [--rate HZ] "
      "[--rss-growth-mb MB] [--fd-slack N] [--expect-page-error TEXT] [-o report.json] "
      "[--markdown report.md] -- POINTRAST serve INPUT [OPTIONS]\n",
      why);
  return 2;
}

bool writeFile(const std::string& path, const std::string& text) {
  std::string temp = path + ".part";
  {
    std::ofstream f(temp, std::ios::binary);
    f << text;
    if (!f.flush()) return false;
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  return !ec;
}

} // namespace

int main(int argc, char** argv) {
  Args args;
  int i = 1;
  for (; i < argc; ++i) {
    std::string k = argv[i];
    if (k == "--") {
      ++i;
      break;
    }
    if (i + 1 >= argc) return usage(("missing value for " + k).c_str());
    std::string v = argv[++i];
    if (k == "--seconds")
      args.seconds = std::stod(v);
    else if (k == "--sample")
      args.sample = std::stod(v);
    else if (k == "--warmup")
      args.warmup = std::stod(v);
    else if (k == "--viewers")
      args.viewers = std::stoi(v);
    else if (k == "--rate")
      args.rate = std::stod(v);
    else if (k == "--rss-growth-mb")
      args.rssGrowthMb = std::stod(v);
    else if (k == "--fd-slack")
      args.fdSlack = std::stoi(v);
    else if (k == "--expect-page-error")
      args.expectPageError = v;
    else if (k == "-o" || k == "--output")
      args.json = v;
    else if (k == "--markdown")
      args.markdown = v;
    else
      return usage(("unknown option " + k).c_str());
  }
  for (; i < argc; ++i)
    args.command.push_back(argv[i]);
  if (args.command.empty()) return usage("no server command after --");
  if (args.seconds <= 0 || args.sample <= 0 || args.rate <= 0 || args.viewers < 1 ||
      args.warmup >= args.seconds)
    return usage(
        "--seconds, --sample, --rate, --viewers must be positive and --warmup shorter than --seconds");

  Server server;
  if (!server.start(args.command)) {
    std::fprintf(stderr, "serve_soak: the server did not start listening\n");
    return 1;
  }
  Sample baseline = sampleProcess(server.pid());
  std::atomic<bool> stop{false};
  Tally tally;
  std::vector<std::thread> clients;
  for (int v = 0; v < args.viewers; ++v)
    clients.emplace_back(viewer, v, std::cref(args), server.port(), std::cref(stop), std::ref(tally));
  clients.emplace_back(misbehave, std::cref(stop), server.port(), std::ref(tally));

  std::vector<Sample> samples;
  auto start = Clock::now();
  bool died = false;
  while (seconds(start) < args.seconds) {
    std::this_thread::sleep_for(
        std::chrono::duration<double>(std::min(args.sample, args.seconds - seconds(start))));
    if (!server.alive()) {
      died = true;
      break;
    }
    Sample s = sampleProcess(server.pid());
    s.t = seconds(start);
    s.clients = server.openClients();
    s.frames = tally.frames;
    samples.push_back(s);
    std::fprintf(stderr, "serve_soak: %6.0f s  rss %7.1f MB  fds %4d  clients %2d  frames %llu\n", s.t,
                 s.rssMb, s.fds, s.clients, static_cast<unsigned long long>(s.frames));
  }
  stop = true;
  for (std::thread& t : clients)
    t.join();
  bool drained = !died && server.waitForNoClients(60);
  Sample quiet = died ? Sample{} : sampleProcess(server.pid());
  int exitCode = server.stop();
  died = died || exitCode != 0;

  // Memory: the largest after the warm-up against the largest during it.
  double warm = baseline.rssMb, peak = 0;
  for (const Sample& s : samples)
    (s.t <= args.warmup ? warm : peak) = std::max(s.t <= args.warmup ? warm : peak, s.rssMb);
  int maxFds = baseline.fds;
  for (const Sample& s : samples)
    maxFds = std::max(maxFds, s.fds);
  bool rssBounded = peak <= warm + args.rssGrowthMb;
  bool fdsBounded = drained && quiet.fds <= baseline.fds + args.fdSlack;
  bool expectedErrorSeen = args.expectPageError.empty();
  for (const auto& [text, n] : tally.pageErrors)
    expectedErrorSeen = expectedErrorSeen || text.find(args.expectPageError) != std::string::npos;
  bool ok = !died && rssBounded && fdsBounded && tally.failures.empty() && expectedErrorSeen;

  Json report;
  std::string command;
  for (const std::string& c : args.command)
    command += (command.empty() ? "" : " ") + c;
  report["server"] = command;
  report["seconds"] = samples.empty() ? 0.0 : samples.back().t;
  report["viewers"] = args.viewers;
  report["rate_hz"] = args.rate;
  report["frames"] = tally.frames.load();
  report["sessions"] = {
      {"viewers", tally.viewerSessions.load()},      {"vanished_mid_frame", tally.vanished.load()},
      {"slow_readers", tally.slowSessions.load()},   {"malformed", tally.badSessions.load()},
      {"malformed_cut_off", tally.badCutOff.load()}, {"idle_sockets", tally.idleSockets.load()},
      {"http_requests", tally.httpRequests.load()}};
  report["server_refusals"] = server.refusals();
  report["page_errors"] = tally.pageErrors;
  report["failures"] = tally.failures;
  report["rss_mb"] = {{"start", baseline.rssMb},
                      {"warm_up_peak", warm},
                      {"peak_after_warm_up", peak},
                      {"allowed_growth", args.rssGrowthMb},
                      {"bounded", rssBounded}};
  report["fds"] = {{"start", baseline.fds},
                   {"peak", maxFds},
                   {"after_clients_left", quiet.fds},
                   {"slack", args.fdSlack},
                   {"bounded", fdsBounded}};
  report["server_exit"] = exitCode;
  report["server_died"] = died;
  report["expected_page_error"] = args.expectPageError;
  report["expected_page_error_seen"] = expectedErrorSeen;
  report["pass"] = ok;
  for (const Sample& s : samples)
    report["samples"].push_back({{"t", std::round(s.t * 10) / 10},
                                 {"rss_mb", std::round(s.rssMb * 10) / 10},
                                 {"fds", s.fds},
                                 {"clients", s.clients},
                                 {"frames", s.frames}});

  std::string md =
      "# serve soak\n\n`" + command + "` for " + std::to_string(int(report["seconds"].get<double>())) +
      " s: " + std::to_string(args.viewers) + " viewer(s) at " + std::to_string(int(args.rate)) +
      " Hz, and clients that vanish mid-frame, read slowly, send malformed messages or idle.\n\n";
  char buffer[512];
  std::snprintf(buffer, sizeof buffer,
                "| result | %s |\n| --- | --- |\n| frames served | %llu |\n| viewer sessions | %llu |\n"
                "| vanished / slow / malformed (cut off) / idle | %llu / %llu / %llu (%llu) / %llu |\n"
                "| RSS MB: start, warm-up peak, peak after | %.1f, %.1f, %.1f (bound +%.0f: %s) |\n"
                "| fds: start, peak, after clients left | %d, %d, %d (%s) |\n| server exit | %d |\n\n",
                ok ? "pass" : "FAIL", static_cast<unsigned long long>(tally.frames.load()),
                static_cast<unsigned long long>(tally.viewerSessions.load()),
                static_cast<unsigned long long>(tally.vanished.load()),
                static_cast<unsigned long long>(tally.slowSessions.load()),
                static_cast<unsigned long long>(tally.badSessions.load()),
                static_cast<unsigned long long>(tally.badCutOff.load()),
                static_cast<unsigned long long>(tally.idleSockets.load()), baseline.rssMb, warm, peak,
                args.rssGrowthMb, rssBounded ? "bounded" : "GREW", baseline.fds, maxFds, quiet.fds,
                fdsBounded ? "bounded" : "LEAKED", exitCode);
  md += buffer;
  if (!tally.pageErrors.empty()) {
    md += "Error messages pages were sent:\n\n";
    for (const auto& [text, n] : tally.pageErrors)
      md += "- " + std::to_string(n) + " x " + text + "\n";
    md += "\n";
  }
  for (const std::string& f : tally.failures)
    md += "- failure: " + f + "\n";
  md += "| s | RSS MB | fds | clients | frames |\n| ---: | ---: | ---: | ---: | ---: |\n";
  size_t stride = std::max<size_t>(1, samples.size() / 30); // at most ~30 rows
  for (size_t k = 0; k < samples.size(); k += stride) {
    const Sample& s = samples[k];
    std::snprintf(buffer, sizeof buffer, "| %.0f | %.1f | %d | %d | %llu |\n", s.t, s.rssMb, s.fds, s.clients,
                  static_cast<unsigned long long>(s.frames));
    md += buffer;
  }
  if (!args.json.empty() && !writeFile(args.json, report.dump(2) + "\n"))
    std::fprintf(stderr, "serve_soak: cannot write %s\n", args.json.c_str());
  if (!args.markdown.empty() && !writeFile(args.markdown, md))
    std::fprintf(stderr, "serve_soak: cannot write %s\n", args.markdown.c_str());
  std::fputs(md.c_str(), stdout);
  if (!ok) {
    std::fprintf(stderr, "serve_soak: FAIL:%s%s%s%s%s\n", died ? " the server died or failed its exit;" : "",
                 rssBounded ? "" : " RSS grew past the bound;", fdsBounded ? "" : " descriptors leaked;",
                 tally.failures.empty() ? "" : " a well-behaved client was refused or cut off;",
                 expectedErrorSeen ? "" : " the expected page error never came;");
    return 1;
  }
  return 0;
}
