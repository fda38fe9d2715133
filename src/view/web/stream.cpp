#include "view/web/stream.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "gpu/timer.h"

namespace pointrast::view::web {

namespace {

// Statistics cover this many recent frames, as the session's do.
constexpr size_t kRecent = 60;

double seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void remember(std::deque<double>& values, double value) {
  values.push_back(value);
  if (values.size() > kRecent) values.pop_front();
}

} // namespace

FrameStream::FrameStream(MessageSink& sink, std::function<void()> progress)
    : sink_(sink), progress_(std::move(progress)), thread_([this] { run(); }) {}

FrameStream::~FrameStream() {
  stop();
}

bool FrameStream::wantsFrame() const {
  std::lock_guard lock(mutex_);
  return !stop_ && (pending_ ? 1 : 0) + inFlight_.size() < kFramesInFlight;
}

void FrameStream::submitFrame(RawFrame frame) {
  std::lock_guard lock(mutex_);
  if (pending_) stats_.framesDropped++;
  pending_ = std::move(frame);
  wake_.notify_one();
}

void FrameStream::submitState(std::string json) {
  std::lock_guard lock(mutex_);
  state_ = std::move(json);
  wake_.notify_one();
}

void FrameStream::submitText(std::string text) {
  std::lock_guard lock(mutex_);
  if (texts_.size() >= kMaxQueuedMessages) return;
  texts_.push_back(std::move(text));
  wake_.notify_one();
}

void FrameStream::submitBinary(std::vector<uint8_t> bytes) {
  std::lock_guard lock(mutex_);
  // Screenshots are large: a client that has not taken the last one gets no second one queued.
  if (!binaries_.empty()) return;
  binaries_.push_back(std::move(bytes));
  wake_.notify_one();
}

void FrameStream::submitClose(uint16_t code, std::string reason) {
  std::lock_guard lock(mutex_);
  close_ = {code, std::move(reason)};
  wake_.notify_one();
}

StreamStats FrameStream::stats() const {
  std::lock_guard lock(mutex_);
  StreamStats s = stats_;
  double now = seconds();
  s.framesPerSecond =
      double(std::count_if(sentTimes_.begin(), sentTimes_.end(), [&](double t) { return now - t <= 1.0; }));
  return s;
}

bool FrameStream::acknowledge(uint32_t frame) {
  {
    std::lock_guard lock(mutex_);
    auto it = std::find(inFlight_.begin(), inFlight_.end(), frame);
    if (it == inFlight_.end()) return false;
    // Frames are drawn in order: acknowledging one acknowledges those before it.
    inFlight_.erase(inFlight_.begin(), it + 1);
  }
  progress_();
  return true;
}

void FrameStream::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    wake_.notify_one();
  }
  if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
}

bool FrameStream::stopped() const {
  std::lock_guard lock(mutex_);
  return stop_;
}

bool FrameStream::idle() const {
  return !pending_ && !state_ && texts_.empty() && binaries_.empty() && !close_;
}

void FrameStream::run() {
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return stop_ || !idle(); });
    if (stop_) return;
    std::deque<std::string> texts = std::move(texts_);
    texts_.clear();
    std::deque<std::vector<uint8_t>> binaries = std::move(binaries_);
    binaries_.clear();
    std::optional<std::string> state = std::exchange(state_, std::nullopt);
    std::optional<RawFrame> frame = std::exchange(pending_, std::nullopt);
    auto close = std::exchange(close_, std::nullopt);
    if (frame) inFlight_.push_back(frame->header.frame);
    lock.unlock();
    // Writes happen without the lock: the render thread keeps submitting meanwhile, and the newest frame
    // replaces the pending one.
    bool alive = true;
    for (const std::string& text : texts)
      alive = alive && sink_.sendText(text);
    for (const std::vector<uint8_t>& bytes : binaries)
      alive = alive && sink_.sendBinary(bytes);
    if (alive && state) alive = sink_.sendText(*state); // the state describes the frame after it
    if (alive && frame) sendFrame(*frame);
    if (close) sink_.sendClose(close->first, close->second);
    lock.lock();
    if (!alive || close) stop_ = true;
  }
}

void FrameStream::sendFrame(RawFrame& frame) {
  auto start = std::chrono::steady_clock::now();
  encoder_.encode(frame.rgba, frame.header.width, frame.header.height, frame.jpeg, jpeg_);
  double encodeMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  frame.header.quality = uint8_t(frame.jpeg.quality);
  frame.header.encodeMs = float(encodeMs);
  message_.resize(kFrameHeaderBytes + jpeg_.size());
  writeFrameHeader(frame.header, message_.data());
  std::memcpy(message_.data() + kFrameHeaderBytes, jpeg_.data(), jpeg_.size());
  bool sent = sink_.sendBinary(message_);
  std::lock_guard lock(mutex_);
  if (!sent) {
    stop_ = true;
    return;
  }
  remember(encodeMs_, encodeMs);
  stats_.encodeMs = gpu::median(std::vector<double>(encodeMs_.begin(), encodeMs_.end()));
  if (frame.header.flags & kFrameFull) {
    stats_.fullBytes = double(message_.size());
  } else {
    remember(motionBytes_, double(message_.size()));
    double sum = 0;
    for (double b : motionBytes_)
      sum += b;
    stats_.motionBytes = sum / double(motionBytes_.size());
  }
  stats_.framesSent++;
  stats_.bytesSent += message_.size();
  double now = seconds();
  sentTimes_.push_back(now);
  while (!sentTimes_.empty() && now - sentTimes_.front() > 1.0)
    sentTimes_.pop_front();
}

} // namespace pointrast::view::web
