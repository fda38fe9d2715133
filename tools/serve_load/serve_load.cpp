// serve_load: a loopback load client for `pointrast serve`. It opens one WebSocket as a browser tab of the
// given canvas size would, orbits the camera by a continuous drag (a pointer move every 1/rate s) and
// measures what a user feels: frames per second received, the time from an input message to the first
// frame that shows it (the frame header echoes the last input sequence number applied), and bytes per
// frame while moving and at rest. Each frame is decoded (TurboJPEG) before it is acknowledged, as a page
// draws it before acknowledging, unless --no-decode.
//
// With --flight (an octree drawn with level of detail) it flies instead: the camera goes low over the cloud
// (wheel steps towards the middle) and pans across it for --seconds by continuous strokes, then jumps
// (standard views, and zooms towards other places) and counts the frames until the server reports the
// view converged (every selected node resident and drawn).
//
//   serve_load --port 8080 [--host 127.0.0.1] [--token T] [--width 1920] [--height 1080] [--seconds 10]
//              [--rate 120] [--isolated 30] [--flight] [--no-decode] [-o result.json] [--markdown result.md]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "view/flight.h"
#include "view/web/jpeg.h"
#include "view/web/protocol.h"
#include "ws_client.h"

namespace {

using Json = nlohmann::json;
using namespace pointrast;

double clockSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Args {
  std::string host = "127.0.0.1", token, output, markdown;
  uint16_t port = 8080;
  uint32_t width = 1920, height = 1080, isolated = 30;
  double seconds = 10, rate = 120;
  bool decode = true, flight = false;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  size_t i = size_t(std::min<double>(double(v.size() - 1), std::floor(p * double(v.size() - 1) + 0.5)));
  return v[i];
}

Json summary(const std::vector<double>& ms) {
  return {{"inputs", ms.size()},
          {"p50", percentile(ms, 0.5)},
          {"p95", percentile(ms, 0.95)},
          {"max", ms.empty() ? 0.0 : *std::max_element(ms.begin(), ms.end())}};
}

struct Frame {
  view::web::FrameHeader header;
  size_t bytes = 0;
  double arrived = 0;
  bool converged = false;            // the state sent with it says the level-of-detail view converged
  std::optional<double> pointsDrawn; // the points its level-of-detail frame drew, from that state
  double received = 0;               // when its message was read, before the JPEG was decoded
  // From its state: how long the oldest input it shows waited on the server before the frame's drawing
  // began, and how long the server's thread took to draw it (upload, render, readback).
  std::optional<double> serverInputWaitMs, serverFrameWallMs;
};

class Load {
public:
  explicit Load(const Args& a) : args_(a) {}
  int run();

private:
  bool connect();
  // Receives until the deadline; frames are decoded, acknowledged and handed to onFrame_.
  void pump(double until);
  std::optional<Frame> waitFrame(double timeout, uint32_t minSeq, bool full);
  uint32_t send(Json message);
  Json motionPhase(double scale);
  Json isolatedLatency();
  Json flightPhase();
  Json jumps();
  int runFlight(const Frame& first, Json result);

  const Args& args_;
  wsclient::Client ws_;
  Json info_, state_;
  uint32_t seq_ = 0;
  std::map<uint32_t, double> sentAt_; // input seq -> send time, until a frame showed it
  std::vector<double> latencies_;     // ms, of the inputs shown since the last reset
  std::vector<Frame> frames_;         // received since the last reset
  std::vector<uint32_t> rgba_;
  // frame id -> its state's lod.converged; none for a source without level of detail, whose full frame
  // (the one drawn at rest) is its final image.
  std::map<uint32_t, std::optional<bool>> convergedByFrame_;
  bool sawLod_ = false; // some state carried level-of-detail statistics
  std::map<uint32_t, double> pointsByFrame_;                      // frame id -> its state's lod.pointsDrawn
  std::map<uint32_t, std::pair<double, double>> serverMsByFrame_; // frame id -> inputWaitMs, frameWallMs
  std::vector<double> receivedLatencies_; // ms, as latencies_ but to the frame's message before decoding
  std::vector<std::pair<uint32_t, double>>
      sentLog_; // every input's seq and send time, since the flight began
};

uint32_t Load::send(Json message) {
  message["seq"] = ++seq_;
  sentAt_[seq_] = clockSeconds();
  sentLog_.emplace_back(seq_, sentAt_[seq_]);
  ws_.sendText(message.dump());
  return seq_;
}

bool Load::connect() {
  std::string target = "/ws" + (args_.token.empty() ? "" : "?token=" + args_.token);
  if (!ws_.connect(args_.host, args_.port, target)) {
    std::fprintf(stderr, "serve_load: no WebSocket at %s:%u%s (HTTP %d)\n", args_.host.c_str(), args_.port,
                 target.c_str(), ws_.response().status);
    return false;
  }
  ws_.sendText(Json{{"t", "resize"}, {"w", args_.width}, {"h", args_.height}}.dump());
  return true;
}

void Load::pump(double until) {
  while (true) {
    double left = until - clockSeconds();
    if (left <= 0) return;
    std::optional<wsclient::Message> m = ws_.receive(left);
    if (!m) return;
    if (m->opcode == 1) {
      Json j = Json::parse(m->text(), nullptr, false);
      if (j.is_object() && j.value("t", "") == "info") info_ = j;
      if (j.is_object() && j.value("t", "") == "state") {
        state_ = j;
        const Json& lod = j.value("stats", Json::object()).value("lod", Json::object());
        if (j.contains("frame") && j["frame"].is_number_unsigned()) {
          std::optional<bool> converged;
          if (!lod.empty()) converged = lod.value("converged", false), sawLod_ = true;
          convergedByFrame_[j["frame"].get<uint32_t>()] = converged;
          if (lod.contains("pointsDrawn") && lod["pointsDrawn"].is_number())
            pointsByFrame_[j["frame"].get<uint32_t>()] = lod["pointsDrawn"].get<double>();
          const Json& stats = j.value("stats", Json::object());
          if (stats.contains("inputWaitMs") && stats["inputWaitMs"].is_number() &&
              stats.contains("frameWallMs") && stats["frameWallMs"].is_number())
            serverMsByFrame_[j["frame"].get<uint32_t>()] = {stats["inputWaitMs"].get<double>(),
                                                            stats["frameWallMs"].get<double>()};
        }
      }
      continue;
    }
    if (m->opcode != 2 || m->data.size() < view::web::kFrameHeaderBytes) continue;
    Frame f;
    f.header = view::web::readFrameHeader(m->data.data());
    if (f.header.magic != view::web::kFrameMagic) continue;
    f.bytes = m->data.size();
    f.received = clockSeconds();
    if (args_.decode) {
      uint32_t w = 0, h = 0;
      view::web::decodeJpeg(
          {m->data.data() + view::web::kFrameHeaderBytes, m->data.size() - view::web::kFrameHeaderBytes}, w,
          h, rgba_);
    }
    f.arrived = clockSeconds();
    if (auto it = convergedByFrame_.find(f.header.frame); it != convergedByFrame_.end()) {
      f.converged = it->second.value_or((f.header.flags & view::web::kFrameFull) != 0);
      convergedByFrame_.erase(convergedByFrame_.begin(), std::next(it));
    }
    if (auto it = pointsByFrame_.find(f.header.frame); it != pointsByFrame_.end()) {
      f.pointsDrawn = it->second;
      pointsByFrame_.erase(pointsByFrame_.begin(), std::next(it));
    }
    if (auto it = serverMsByFrame_.find(f.header.frame); it != serverMsByFrame_.end()) {
      f.serverInputWaitMs = it->second.first;
      f.serverFrameWallMs = it->second.second;
      serverMsByFrame_.erase(serverMsByFrame_.begin(), std::next(it));
    }
    ws_.sendText(Json{{"t", "ack"}, {"frame", f.header.frame}}.dump());
    // Every input up to the frame's sequence number is shown by it.
    for (auto it = sentAt_.begin(); it != sentAt_.end() && it->first <= f.header.seq;) {
      latencies_.push_back((f.arrived - it->second) * 1e3);
      receivedLatencies_.push_back((f.received - it->second) * 1e3);
      it = sentAt_.erase(it);
    }
    frames_.push_back(f);
  }
}

std::optional<Frame> Load::waitFrame(double timeout, uint32_t minSeq, bool full) {
  double deadline = clockSeconds() + timeout;
  size_t seen = frames_.size();
  while (clockSeconds() < deadline) {
    pump(std::min(deadline, clockSeconds() + 0.05));
    for (size_t i = seen; i < frames_.size(); ++i)
      if (frames_[i].header.seq >= minSeq && (!full || (frames_[i].header.flags & view::web::kFrameFull)))
        return frames_[i];
    seen = frames_.size();
    if (!ws_.open()) break;
  }
  return std::nullopt;
}

Json Load::motionPhase(double scale) {
  send({{"t", "stream"}, {"motionScale", scale}});
  pump(clockSeconds() + 0.5);
  frames_.clear();
  latencies_.clear();
  receivedLatencies_.clear();
  sentAt_.clear();
  send({{"t", "down"}, {"b", 0}, {"x", 0.5}, {"y", 0.5}});
  double start = clockSeconds(), next = start;
  // A circle of a quarter canvas radius, once every 4 s: the camera swings back and forth without pause.
  while (clockSeconds() - start < args_.seconds) {
    double t = clockSeconds() - start;
    send({{"t", "move"},
          {"x", 0.5 + 0.25 * std::sin(t * M_PI / 2)},
          {"y", 0.5 + 0.25 * (1 - std::cos(t * M_PI / 2))}});
    next += 1.0 / args_.rate;
    pump(next);
  }
  double elapsed = clockSeconds() - start;
  std::vector<Frame> moving = frames_;
  std::vector<double> latencies = latencies_;
  uint32_t up = send({{"t", "up"}, {"b", 0}, {"x", 0.5}, {"y", 0.5}});
  double upAt = clockSeconds();
  std::optional<Frame> rest = waitFrame(5.0, up, true);
  double motionBytes = 0;
  size_t motionFrames = 0;
  for (const Frame& f : moving)
    if (!(f.header.flags & view::web::kFrameFull)) {
      motionBytes += double(f.bytes);
      motionFrames++;
    }
  Json stats = state_.is_object() ? state_.value("stats", Json::object()) : Json::object();
  Json phase = {{"motion_scale", scale},
                {"seconds", elapsed},
                {"frames", moving.size()},
                {"frames_per_second", double(moving.size()) / elapsed},
                {"motion_frames", motionFrames},
                {"motion_frame_size",
                 moving.empty() ? Json() : Json{moving.back().header.width, moving.back().header.height}},
                {"bytes_per_frame_moving", motionFrames ? motionBytes / double(motionFrames) : 0.0},
                {"input_to_frame_ms", summary(latencies)},
                {"server_render_ms", stats.value("renderMs", 0.0)},
                {"server_encode_ms", stats.value("encodeMs", 0.0)},
                {"server_host_ms", stats.value("hostMs", 0.0)},
                {"frames_dropped", stats.value("framesDropped", 0)}};
  if (rest) {
    phase["bytes_per_frame_at_rest"] = rest->bytes;
    phase["rest_frame_after_release_ms"] = (rest->arrived - upAt) * 1e3;
  }
  return phase;
}

// The time from one input after a pause to its frame: a discrete change, rendered at full quality.
Json Load::isolatedLatency() {
  std::vector<double> ms;
  for (uint32_t i = 0; i < args_.isolated; ++i) {
    pump(clockSeconds() + 0.4);
    send({{"t", "down"}, {"b", 0}, {"x", 0.5}, {"y", 0.5}});
    double x = 0.5 + (i % 2 ? -0.02 : 0.02);
    double sent = clockSeconds();
    uint32_t s = send({{"t", "move"}, {"x", x}, {"y", 0.5}});
    std::optional<Frame> f = waitFrame(5.0, s, false);
    if (f) ms.push_back((f->arrived - sent) * 1e3);
    send({{"t", "up"}, {"b", 0}, {"x", x}, {"y", 0.5}});
  }
  return summary(ms);
}

// The targets a browser user needs: a smooth drag, and a frame soon after each input.
constexpr double kTargetFramesPerSecond = 30;
constexpr double kTargetLatencyMs = 50;

std::string format(const char* pattern, double a, double b = 0, double c = 0) {
  char text[160];
  std::snprintf(text, sizeof text, pattern, a, b, c);
  return text;
}

// The result as a Markdown table: one row per motion phase, the isolated inputs below.
std::string markdown(const Json& r) {
  std::string md = "# pointrast serve: one client at " + std::to_string(r["width"].get<uint32_t>()) + "x" +
                   std::to_string(r["height"].get<uint32_t>()) + "\n\n";
  md += "Device " + r["device"].get<std::string>() + ", " + r["input"].get<std::string>() + " (" +
        std::to_string(r["points"].get<uint64_t>()) + " points), method " + r["method"].get<std::string>() +
        "; the load client `serve_load` over loopback, a continuous drag at " +
        format("%.0f", r["input_rate_hz"].get<double>()) + " pointer moves/s, each frame decoded before " +
        "its acknowledgement. Targets: >= " + format("%.0f", kTargetFramesPerSecond) +
        " frames/s, <= " + format("%.0f", kTargetLatencyMs) + " ms from input to frame.\n\n";
  md += "| motion scale | frame while moving | frames/s | input to frame p50 (ms) | p95 (ms) | KiB/frame "
        "moving "
        "| KiB/frame at rest | server render (ms) | server encode (ms) |\n";
  md += "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const Json& p : r["phases"]) {
    const Json& size = p["motion_frame_size"];
    md += "| " + format("%.2f", p["motion_scale"].get<double>()) + " | " +
          (size.is_array()
               ? std::to_string(size[0].get<uint32_t>()) + "x" + std::to_string(size[1].get<uint32_t>())
               : std::string("-")) +
          " | " + format("%.1f", p["frames_per_second"].get<double>()) + " | " +
          format("%.1f | %.1f", p["input_to_frame_ms"]["p50"].get<double>(),
                 p["input_to_frame_ms"]["p95"].get<double>()) +
          " | " + format("%.0f", p["bytes_per_frame_moving"].get<double>() / 1024) + " | " +
          format("%.0f", p.value("bytes_per_frame_at_rest", 0.0) / 1024) + " | " +
          format("%.2f | %.2f", p["server_render_ms"].get<double>(), p["server_encode_ms"].get<double>()) +
          " |\n";
  }
  const Json& iso = r["isolated_input_to_frame_ms"];
  md += "\nOne input after a pause (" + std::to_string(iso["inputs"].get<size_t>()) +
        " inputs), to its frame: " +
        format("p50 %.1f ms, p95 %.1f ms, max %.1f ms", iso["p50"].get<double>(), iso["p95"].get<double>(),
               iso["max"].get<double>()) +
        ".\n";
  return md;
}

bool writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.close();
  if (out) return true;
  std::fprintf(stderr, "serve_load: cannot write %s\n", path.c_str());
  return false;
}

// Low over the cloud, then across it: wheel steps towards a point below the middle of the canvas bring the
// camera down, and horizontal strokes of a pan drag (right button, view::flightStroke: the desktop viewer's
// `--flight` plays the same) carry it sideways at that height, across the cloud and back, for --seconds, a
// pointer move every 1/rate s. Every node the flight needs is streamed while it flies; a frame never waits
// for one.
// The machine's own scheduling delays while the flight runs, apart from pointrast: a thread of this process
// that sleeps 1 ms at a time and records how late it wakes, and the share of CPU time the hypervisor took
// (the steal column of /proc/stat).
class Canary {
public:
  Canary()
      : stealFrom_(steal()), thread_([this] {
          while (!stop_) {
            const double t = clockSeconds();
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
            late_.push_back(std::max(0.0, (clockSeconds() - t) * 1e3 - 1.0));
          }
        }) {}
  Json finish() {
    stop_ = true;
    thread_.join();
    const auto to = steal();
    Json j = {{"late_ms",
               {{"p50", percentile(late_, 0.5)},
                {"p95", percentile(late_, 0.95)},
                {"p99", percentile(late_, 0.99)},
                {"max", late_.empty() ? 0.0 : *std::max_element(late_.begin(), late_.end())},
                {"wakes", late_.size()}}}};
    if (to.second > stealFrom_.second)
      j["steal_percent"] =
          100.0 * double(to.first - stealFrom_.first) / double(to.second - stealFrom_.second);
    return j;
  }

private:
  // Steal and total jiffies of all CPUs.
  static std::pair<uint64_t, uint64_t> steal() {
    std::ifstream in("/proc/stat");
    std::string cpu;
    uint64_t v[8] = {}, total = 0;
    in >> cpu;
    for (uint64_t& x : v) {
      in >> x;
      total += x;
    }
    return {v[7], total};
  }
  std::pair<uint64_t, uint64_t> stealFrom_;
  std::atomic<bool> stop_{false};
  std::vector<double> late_;
  std::thread thread_;
};

Json Load::flightPhase() {
  send({{"t", "stream"}, {"motionScale", 0.5}});
  for (int i = 0; i < 6; ++i) {
    uint32_t s = send({{"t", "wheel"}, {"x", 0.5}, {"y", 0.6}, {"steps", 2}});
    waitFrame(30.0, s, false);
  }
  pump(clockSeconds() + 0.5);
  frames_.clear();
  latencies_.clear();
  receivedLatencies_.clear();
  sentAt_.clear();
  Canary canary;
  sentLog_.clear();
  double start = clockSeconds(), next = start;
  const double stroke = 1.5; // seconds a stroke
  bool down = false;
  uint64_t strokes = 0;
  double strokeStart = start;
  auto pointer = [](const char* type, glm::dvec2 at) {
    Json m = {{"t", type}, {"x", at.x}, {"y", at.y}};
    if (std::strcmp(type, "move") != 0) m["b"] = 2;
    return m;
  };
  while (clockSeconds() - start < args_.seconds) {
    double now = clockSeconds();
    if (!down) {
      send(pointer("down", view::flightStroke(strokes, 0.0)));
      down = true;
      strokeStart = now;
    }
    double u = std::min(1.0, (now - strokeStart) / stroke);
    send(pointer("move", view::flightStroke(strokes, u)));
    if (u >= 1.0) {
      send(pointer("up", view::flightStroke(strokes, 1.0)));
      down = false;
      ++strokes;
    }
    // A pump that returned late does not make the next moves come in a burst: a page sends at most one
    // move per animation frame (--rate stands for the display's refresh rate), besides an acknowledgement
    // per frame, and the server cuts off a client that sends faster than a page does.
    next = std::max(next + 1.0 / args_.rate, clockSeconds());
    pump(next);
  }
  if (down) send(pointer("up", view::flightStroke(strokes, 1.0)));
  double elapsed = clockSeconds() - start;
  Json machine = canary.finish();
  std::vector<Frame> flown = frames_;
  std::vector<double> latencies = latencies_;
  const std::vector<double> receivedLatencies = receivedLatencies_;
  size_t converged = 0;
  std::vector<double> points, renderMs, encodeMs, gapMs, decodeMs, waitMs, wallMs;
  for (size_t i = 0; i < flown.size(); ++i) {
    const Frame& f = flown[i];
    converged += f.converged;
    decodeMs.push_back((f.arrived - f.received) * 1e3);
    if (f.serverInputWaitMs) waitMs.push_back(*f.serverInputWaitMs);
    if (f.serverFrameWallMs) wallMs.push_back(*f.serverFrameWallMs);
    if (f.pointsDrawn) points.push_back(*f.pointsDrawn);
    renderMs.push_back(f.header.renderMs);
    encodeMs.push_back(f.header.encodeMs);
    if (i > 0) gapMs.push_back((f.arrived - flown[i - 1].arrived) * 1e3);
  }
  auto spread = [](const std::vector<double>& ms) {
    return Json{{"p50", percentile(ms, 0.5)},
                {"p95", percentile(ms, 0.95)},
                {"max", ms.empty() ? 0.0 : *std::max_element(ms.begin(), ms.end())}};
  };
  Json out = {{"seconds", elapsed},
              {"frames", flown.size()},
              {"frames_per_second", double(flown.size()) / elapsed},
              {"frames_converged", converged},
              {"input_to_frame_ms", summary(latencies)},
              // Where a late frame's time went: the server's render and JPEG encode of each frame (its
              // header), and the time between frames arriving here.
              {"frame_render_ms", spread(renderMs)},
              {"frame_encode_ms", spread(encodeMs)},
              {"frame_gap_ms", spread(gapMs)},
              // The input's way split up: to the frame's message read here (before decoding), the JPEG
              // decode here, the oldest input's wait on the server before its frame began, and the
              // server thread's time drawing a frame.
              {"input_to_frame_received_ms", summary(receivedLatencies)},
              {"frame_decode_ms", spread(decodeMs)},
              {"server_input_wait_ms", spread(waitMs)},
              {"server_frame_wall_ms", spread(wallMs)},
              {"machine", machine}};
  // Frame by frame (ms from the flight's start): when each arrived and was decoded, its input sequence
  // number, and the server's figures, to see where a late input's time went.
  Json trace = Json::array();
  for (const Frame& f : flown)
    trace.push_back({(f.received - start) * 1e3, (f.arrived - start) * 1e3, f.header.seq, f.header.frame,
                     f.header.renderMs, f.header.encodeMs, f.serverInputWaitMs.value_or(-1),
                     f.serverFrameWallMs.value_or(-1)});
  out["trace_columns"] = {
      "received_ms",          "decoded_ms",          "seq", "frame", "render_ms", "encode_ms",
      "server_input_wait_ms", "server_frame_wall_ms"};
  out["trace"] = trace;
  Json sends = Json::array();
  for (const auto& [seq, at] : sentLog_)
    sends.push_back({seq, (at - start) * 1e3});
  out["sent"] = sends;
  if (!points.empty()) {
    std::sort(points.begin(), points.end());
    out["points_drawn"] = {
        {"median", points[points.size() / 2]}, {"min", points.front()}, {"max", points.back()}};
  }
  return out;
}

// Jumps: a standard view (a key), then a zoom towards another place (wheel steps); after each, the frames
// the server sends until one says the view converged. A frame at rest is sent only while the view changes,
// so the count is the number of frames it took to refine.
Json Load::jumps() {
  struct Jump {
    const char* name;
    Json message;
  };
  const std::vector<Jump> list = {
      {"top view", {{"t", "key"}, {"key", "ViewTop"}, {"down", true}}},
      {"zoom at 0.3,0.3", {{"t", "wheel"}, {"x", 0.3}, {"y", 0.3}, {"steps", 12}}},
      {"front view", {{"t", "key"}, {"key", "ViewFront"}, {"down", true}}},
      {"zoom at 0.7,0.6", {{"t", "wheel"}, {"x", 0.7}, {"y", 0.6}, {"steps", 12}}},
      {"left view", {{"t", "key"}, {"key", "ViewLeft"}, {"down", true}}},
      {"zoom at 0.5,0.7", {{"t", "wheel"}, {"x", 0.5}, {"y", 0.7}, {"steps", 14}}},
      {"overview", {{"t", "key"}, {"key", "ViewIso"}, {"down", true}}},
      {"zoom at 0.6,0.4", {{"t", "wheel"}, {"x", 0.6}, {"y", 0.4}, {"steps", 14}}},
  };
  Json out = Json::array();
  for (const Jump& jump : list) {
    pump(clockSeconds() + 0.3);
    frames_.clear();
    double sent = clockSeconds();
    uint32_t s = send(jump.message);
    if (jump.message["t"] == "key") send({{"t", "key"}, {"key", jump.message["key"]}, {"down", false}});
    // Frames until one that shows the jump and says the view converged; 30 s is the failure bound.
    std::optional<size_t> convergedAt;
    double deadline = sent + 30.0;
    size_t seen = 0;
    while (!convergedAt && clockSeconds() < deadline && ws_.open()) {
      pump(std::min(deadline, clockSeconds() + 0.05));
      for (; seen < frames_.size(); ++seen) {
        const Frame& f = frames_[seen];
        if (f.header.seq >= s && f.converged) {
          convergedAt = seen;
          break;
        }
      }
    }
    size_t shown = 0;
    for (size_t i = 0; i < frames_.size() && (!convergedAt || i <= *convergedAt); ++i)
      shown += frames_[i].header.seq >= s;
    Json r = {{"jump", jump.name}, {"converged", bool(convergedAt)}, {"frames_to_converge", shown}};
    if (convergedAt) r["ms_to_converge"] = (frames_[*convergedAt].arrived - sent) * 1e3;
    out.push_back(r);
  }
  return out;
}

int Load::runFlight(const Frame& first, Json result) {
  (void)first;
  Json flight = flightPhase();
  Json jumped = jumps();
  result["flight"] = flight;
  result["jumps"] = jumped;
  size_t worst = 0;
  bool all = true;
  for (const Json& j : jumped) {
    worst = std::max(worst, j["frames_to_converge"].get<size_t>());
    all = all && j["converged"].get<bool>();
  }
  result["jumps_all_converged"] = all;
  result["jump_frames_to_converge_max"] = worst;
  // Frames that draw nothing are fast and measure nothing: a flight whose median frame drew no point failed.
  const bool drew = !flight.contains("points_drawn") || flight["points_drawn"]["median"].get<double>() > 0;
  result["flight_drew_points"] = drew;
  std::string text = result.dump(2);
  std::printf("%s\n", text.c_str());
  std::fprintf(
      stderr,
      "flight: %.1f frames/s at %ux%u, input to frame p50 %.1f ms p95 %.1f ms; jumps: %s, at most %zu "
      "frames to converge\n",
      flight["frames_per_second"].get<double>(), args_.width, args_.height,
      flight["input_to_frame_ms"]["p50"].get<double>(), flight["input_to_frame_ms"]["p95"].get<double>(),
      all ? "all converged" : "NOT all converged", worst);
  if (!drew)
    std::fprintf(stderr, "serve_load: the flight's median frame drew no points: the camera left the cloud or "
                         "went under its ground, so the figures time empty frames\n");
  if (!args_.output.empty() && !writeFile(args_.output, text + "\n")) return 1;
  if (!args_.markdown.empty()) {
    std::string md = std::string("# pointrast serve: a flight") +
                     (sawLod_ ? " with level of detail" : ", the cloud drawn whole") + ", one client at " +
                     std::to_string(args_.width) + "x" + std::to_string(args_.height) + "\n\n";
    md += "Device " + result["device"].get<std::string>() + ", " + result["input"].get<std::string>() +
          ", method " + result["method"].get<std::string>() +
          "; `serve_load --flight` over loopback: low over the cloud, pan strokes across it at " +
          format("%.0f", args_.rate) + " pointer moves/s, then jumps.\n\n";
    md += "| phase | frames/s | input to frame p50 (ms) | p95 (ms) | points drawn a frame (median) |\n"
          "| --- | ---: | ---: | ---: | ---: |\n";
    md += "| flight | " + format("%.1f", flight["frames_per_second"].get<double>()) + " | " +
          format("%.1f | %.1f", flight["input_to_frame_ms"]["p50"].get<double>(),
                 flight["input_to_frame_ms"]["p95"].get<double>()) +
          " | " +
          (flight.contains("points_drawn") ? format("%.0f", flight["points_drawn"]["median"].get<double>())
                                           : std::string("-")) +
          " |\n\n";
    // Where the flight's input-to-frame time went, p50 / p95 / max in ms.
    auto row = [&](const char* what, const Json& s) {
      return std::string("| ") + what + " | " +
             format("%.1f | %.1f | %.1f", s["p50"].get<double>(), s["p95"].get<double>(),
                    s["max"].get<double>()) +
             " |\n";
    };
    md += "| flight, ms | p50 | p95 | max |\n| --- | ---: | ---: | ---: |\n";
    md += row("input to frame shown (decoded here)", flight["input_to_frame_ms"]);
    md += row("input to frame received (before decoding)", flight["input_to_frame_received_ms"]);
    md += row("server: oldest input's wait before its frame began", flight["server_input_wait_ms"]);
    md += row("server: drawing a frame (upload, render, readback)", flight["server_frame_wall_ms"]);
    md += row("server: GPU render", flight["frame_render_ms"]);
    md += row("server: JPEG encode", flight["frame_encode_ms"]);
    md += row("here: JPEG decode", flight["frame_decode_ms"]);
    md += row("between frames arriving", flight["frame_gap_ms"]);
    if (flight.contains("machine")) {
      const Json& m = flight["machine"];
      md +=
          "\nThe machine while flying, apart from pointrast: a thread sleeping 1 ms at a time woke late by " +
          format("p50 %.2f, p95 %.2f, p99 %.2f", m["late_ms"]["p50"].get<double>(),
                 m["late_ms"]["p95"].get<double>(), m["late_ms"]["p99"].get<double>()) +
          format(", max %.1f ms", m["late_ms"]["max"].get<double>()) +
          (m.contains("steal_percent")
               ? format("; the hypervisor took %.2f %% of CPU time (steal)", m["steal_percent"].get<double>())
               : std::string()) +
          ".\n";
    }
    md += "\n| jump | converged | frames to converge | ms |\n| --- | --- | ---: | ---: |\n";
    for (const Json& j : jumped)
      md += "| " + j["jump"].get<std::string>() + " | " + (j["converged"].get<bool>() ? "yes" : "no") +
            " | " + std::to_string(j["frames_to_converge"].get<size_t>()) + " | " +
            format("%.0f", j.value("ms_to_converge", 0.0)) + " |\n";
    if (!writeFile(args_.markdown, md)) return 1;
  }
  return all && drew ? 0 : 1;
}

int Load::run() {
  if (!connect()) return 1;
  std::optional<Frame> first = waitFrame(300.0, 0, true);
  if (!first) {
    std::fprintf(stderr, "serve_load: no frame from the server\n");
    return 1;
  }
  Json result = {{"tool", "serve_load"},
                 {"server", args_.host + ":" + std::to_string(args_.port)},
                 {"device", info_.value("device", "")},
                 {"input", info_.value("input", "")},
                 {"points", info_.value("points", 0)},
                 {"width", args_.width},
                 {"height", args_.height},
                 {"method", state_.is_object() ? state_["settings"].value("method", "") : ""},
                 {"decode", args_.decode},
                 {"input_rate_hz", args_.rate},
                 {"first_frame_bytes", first->bytes}};
  if (args_.flight) return runFlight(*first, result);
  Json phases = Json::array();
  for (double scale : {0.5, 1.0})
    phases.push_back(motionPhase(scale));
  result["phases"] = phases;
  result["isolated_input_to_frame_ms"] = isolatedLatency();
  std::string text = result.dump(2);
  std::printf("%s\n", text.c_str());
  for (const Json& p : phases)
    std::fprintf(
        stderr,
        "motion scale %.2f: %.1f frames/s at %ux%u canvas, input to frame p50 %.1f ms p95 %.1f ms, %.0f KiB "
        "moving, %.0f KiB at rest\n",
        p["motion_scale"].get<double>(), p["frames_per_second"].get<double>(), args_.width, args_.height,
        p["input_to_frame_ms"]["p50"].get<double>(), p["input_to_frame_ms"]["p95"].get<double>(),
        p["bytes_per_frame_moving"].get<double>() / 1024, p.value("bytes_per_frame_at_rest", 0.0) / 1024);
  if (!args_.output.empty() && !writeFile(args_.output, text + "\n")) return 1;
  if (!args_.markdown.empty() && !writeFile(args_.markdown, markdown(result))) return 1;
  return 0;
}

bool parse(int argc, char** argv, Args& a) {
  for (int i = 1; i < argc; ++i) {
    std::string k = argv[i];
    auto value = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (k == "--host")
      a.host = value();
    else if (k == "--port")
      a.port = uint16_t(std::stoul(value()));
    else if (k == "--token")
      a.token = value();
    else if (k == "--width")
      a.width = uint32_t(std::stoul(value()));
    else if (k == "--height")
      a.height = uint32_t(std::stoul(value()));
    else if (k == "--seconds")
      a.seconds = std::stod(value());
    else if (k == "--rate")
      a.rate = std::stod(value());
    else if (k == "--isolated")
      a.isolated = uint32_t(std::stoul(value()));
    else if (k == "--flight")
      a.flight = true;
    else if (k == "--no-decode")
      a.decode = false;
    else if (k == "-o" || k == "--output")
      a.output = value();
    else if (k == "--markdown")
      a.markdown = value();
    else
      return false;
  }
  return a.rate > 0 && a.seconds > 0;
}

} // namespace

int main(int argc, char** argv) {
  Args args;
  try {
    if (!parse(argc, argv, args)) {
      std::fprintf(
          stderr,
          "usage: serve_load --port P [--host H] [--token T] [--width W] [--height H] [--seconds S] "
          "[--rate HZ] [--isolated N] [--flight] [--no-decode] [-o result.json] [--markdown result.md]\n");
      return 1;
    }
  } catch (const std::exception&) {
    std::fprintf(stderr, "serve_load: bad number in the options\n");
    return 1;
  }
  Load load(args);
  return load.run();
}
