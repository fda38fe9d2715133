// A client's stream: what the render thread hands over and the sender thread that encodes and sends it, so
// that neither JPEG encoding nor a slow network ever holds up the renderer. The newest frame wins: a frame
// the sender has not taken yet is replaced by a newer one, never queued behind it; and at most
// kFramesInFlight frames are on their way (taken, encoded, sent, not yet acknowledged as drawn by the
// page), so a slow client gets fewer frames, not later ones, and costs no GPU time while it catches up.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "view/web/jpeg.h"
#include "view/web/protocol.h"

namespace pointrast::view::web {

constexpr uint32_t kFramesInFlight = 2;
// Text messages waiting for the sender (picks, camera lines, errors) beyond this are dropped: a client that
// does not read cannot make the server hold more.
constexpr size_t kMaxQueuedMessages = 64;

// Where a stream's bytes go: the WebSocket, or a test's buffer. Each returns false once the connection is
// gone; called from the sender thread only.
class MessageSink {
public:
  virtual ~MessageSink() = default;
  virtual bool sendText(std::string_view text) = 0;
  virtual bool sendBinary(std::span<const uint8_t> bytes) = 0;
  virtual void sendClose(uint16_t code, std::string_view reason) = 0;
};

// A rendered image on its way to the encoder.
struct RawFrame {
  std::vector<uint32_t> rgba; // header.width x header.height, row 0 at the top
  FrameHeader header;         // id, seq, sizes, flags and render time; quality and encode time set here
  JpegOptions jpeg;
};

struct StreamStats {
  uint64_t framesSent = 0, framesDropped = 0, bytesSent = 0;
  double encodeMs = 0;        // median of the recent frames
  double motionBytes = 0;     // mean JPEG bytes of the recent motion frames
  double fullBytes = 0;       // of the last full frame
  double framesPerSecond = 0; // frames sent over the last second
};

class FrameStream {
public:
  // Starts the sender thread. `progress` is called (from any thread) when an acknowledgement frees a slot
  // for another frame: the render thread's cue to look at this client again.
  FrameStream(MessageSink& sink, std::function<void()> progress);
  ~FrameStream(); // stop()
  FrameStream(const FrameStream&) = delete;
  FrameStream& operator=(const FrameStream&) = delete;

  // Render thread.
  bool wantsFrame() const; // fewer than kFramesInFlight frames pending or in flight
  void submitFrame(RawFrame frame);
  void submitState(std::string json); // the newest state replaces one not yet sent
  void submitText(std::string text);
  void submitBinary(std::vector<uint8_t> bytes);
  void submitClose(uint16_t code, std::string reason);
  StreamStats stats() const;

  // Any thread: a frame the page has drawn. False when that frame is not in flight (a client's lie).
  bool acknowledge(uint32_t frame);
  // Stops the sender after the write it is in; idempotent. No sink call happens after it returns.
  void stop();
  bool stopped() const;

private:
  void run();
  void sendFrame(RawFrame& frame);
  bool idle() const;

  MessageSink& sink_;
  std::function<void()> progress_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<RawFrame> pending_;
  std::optional<std::string> state_;
  std::deque<std::string> texts_;
  std::deque<std::vector<uint8_t>> binaries_;
  std::optional<std::pair<uint16_t, std::string>> close_;
  std::deque<uint32_t> inFlight_; // ids sent and not yet acknowledged, oldest first
  bool stop_ = false;
  StreamStats stats_;
  std::deque<double> encodeMs_, motionBytes_;
  std::deque<double> sentTimes_; // seconds, for frames per second
  JpegEncoder encoder_;
  std::vector<uint8_t> jpeg_, message_;
  std::thread thread_;
};

} // namespace pointrast::view::web
