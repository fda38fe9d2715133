// A client's stream without a network: the newest frame wins, at most kFramesInFlight frames are out
// unacknowledged, acknowledgements of frames never sent are refused, and a dead sink stops the sender.
#include "view/web/stream.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

namespace pointrast::view::web {
namespace {

using namespace std::chrono_literals;

// Records what the sender wrote; can be held (a slow network) and can fail (a closed connection).
class FakeSink : public MessageSink {
public:
  bool sendText(std::string_view text) override { return record(std::string(text), false); }
  bool sendBinary(std::span<const uint8_t> bytes) override {
    return record(std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()), true);
  }
  void sendClose(uint16_t code, std::string_view) override {
    std::lock_guard lock(mutex_);
    closeCode = code;
    changed_.notify_all();
  }
  void hold(bool on) {
    std::lock_guard lock(mutex_);
    held_ = on;
    changed_.notify_all();
  }
  // The bounds only fail a sender that hangs.
  bool waitFor(size_t frames, std::chrono::milliseconds timeout = 60s) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return frameIds.size() >= frames; });
  }
  // Until `writes` messages have reached the sink (a held one waits in it).
  bool waitForWrites(size_t writes, std::chrono::milliseconds timeout = 60s) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return writes_ >= writes; });
  }
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<uint32_t> frameIds;
  std::vector<std::string> texts;
  bool held_ = false, fail = false;
  int closeCode = 0;

private:
  size_t writes_ = 0;
  bool record(std::string data, bool binary) {
    std::unique_lock lock(mutex_);
    ++writes_;
    changed_.notify_all();
    changed_.wait(lock, [&] { return !held_; });
    if (fail) return false;
    if (binary)
      frameIds.push_back(readFrameHeader(reinterpret_cast<const uint8_t*>(data.data())).frame);
    else
      texts.push_back(std::move(data));
    changed_.notify_all();
    return true;
  }
};

RawFrame frame(uint32_t id) {
  RawFrame f;
  f.header.frame = id;
  f.header.width = f.header.viewWidth = 8;
  f.header.height = f.header.viewHeight = 4;
  f.rgba.assign(32, 0xFF336699u);
  return f;
}

TEST(FrameStream, TheNewestFrameWinsAndTwoAreInFlightAtMost) {
  FakeSink sink;
  std::atomic<int> progress{0};
  FrameStream stream(sink, [&] { progress++; });
  EXPECT_TRUE(stream.wantsFrame());
  sink.hold(true); // the network stalls while frame 1 is being written
  stream.submitFrame(frame(1));
  ASSERT_TRUE(sink.waitForWrites(1)); // frame 1 is being written
  stream.submitFrame(frame(2));
  EXPECT_FALSE(stream.wantsFrame()); // 1 in flight, 2 pending
  stream.submitFrame(frame(3));      // replaces 2: a stalled client never queues frames
  sink.hold(false);
  ASSERT_TRUE(sink.waitFor(2));
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(sink.frameIds, (std::vector<uint32_t>{1, 3}));
  EXPECT_EQ(stream.stats().framesDropped, 1u);
  EXPECT_FALSE(stream.wantsFrame());   // 1 and 3 await their acknowledgements
  EXPECT_FALSE(stream.acknowledge(2)); // never sent
  EXPECT_TRUE(stream.acknowledge(1));
  EXPECT_TRUE(stream.wantsFrame());
  EXPECT_TRUE(stream.acknowledge(3));
  EXPECT_FALSE(stream.acknowledge(3)); // twice
  EXPECT_EQ(progress.load(), 2);
  EXPECT_EQ(stream.stats().framesSent, 2u);
}

TEST(FrameStream, TheStateGoesBeforeItsFrameAndTextsKeepTheirOrder) {
  FakeSink sink;
  FrameStream stream(sink, [] {});
  sink.hold(true);
  stream.submitText("a");
  stream.submitText("b");
  stream.submitState("old state");
  stream.submitState("new state"); // replaces the unsent one
  stream.submitFrame(frame(1));
  sink.hold(false);
  ASSERT_TRUE(sink.waitFor(1));
  std::lock_guard lock(sink.mutex_);
  EXPECT_EQ(sink.texts, (std::vector<std::string>{"a", "b", "new state"}));
}

TEST(FrameStream, ADeadConnectionStopsTheSender) {
  FakeSink sink;
  sink.fail = true;
  FrameStream stream(sink, [] {});
  stream.submitFrame(frame(1));
  for (int i = 0; i < 100 && !stream.stopped(); ++i)
    std::this_thread::sleep_for(10ms);
  EXPECT_TRUE(stream.stopped());
  EXPECT_FALSE(stream.wantsFrame());
}

TEST(FrameStream, CloseIsSentLast) {
  FakeSink sink;
  FrameStream stream(sink, [] {});
  stream.submitText("bye");
  stream.submitClose(1001, "going away");
  for (int i = 0; i < 100 && !stream.stopped(); ++i)
    std::this_thread::sleep_for(10ms);
  EXPECT_TRUE(stream.stopped());
  std::lock_guard lock(sink.mutex_);
  EXPECT_EQ(sink.closeCode, 1001);
  EXPECT_EQ(sink.texts, std::vector<std::string>{"bye"});
}

} // namespace
} // namespace pointrast::view::web
