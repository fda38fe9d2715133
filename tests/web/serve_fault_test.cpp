// `pointrast serve` when its GPU fails under it: a lost device, injected with the test hook
// POINTRAST_INJECT_DEVICE_LOST (the short soak of clients coming and going is the ctest serve_soak_short).
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <optional>
#include <thread>

#include <gtest/gtest.h>

#include "serve_harness.h"
#include "view/web/protocol.h"
#include "ws_client.h"

namespace pointrast::test {
namespace {

using wsclient::Client;

// The environment variable set while a server process is started (it inherits it), unset after.
class ScopedEnv {
public:
  ScopedEnv(const char* name, const char* value) : name_(name) { setenv(name, value, 1); }
  ~ScopedEnv() { unsetenv(name_); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
  const char* name_;
};

// The device is lost at the 40th submission (the upload, then one or two a frame): a client that keeps
// zooming meets it mid-session. The page reads why, its connection closes, and the process exits 1 within
// 5 s with one line on stderr.
TEST(ServeFaults, ALostDeviceTellsThePageClosesAndExitsWithOneLine) {
  std::optional<ServeProcess> server;
  {
    ScopedEnv inject("POINTRAST_INJECT_DEVICE_LOST", "40");
    server.emplace("terrain --points 20000");
  }
  ASSERT_TRUE(server->listening()) << server->stderrText();
  Client ws;
  ASSERT_TRUE(ws.connect("127.0.0.1", server->port(), "/ws"));
  ws.sendText(Json{{"t", "resize"}, {"w", 64}, {"h", 48}}.dump());
  std::string error;
  bool closed = false;
  int frames = 0;
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(180);
  while (!closed && std::chrono::steady_clock::now() < deadline) {
    auto m = ws.receive(60);
    if (!m) {
      closed = !ws.open();
      break;
    }
    if (m->opcode == 8) {
      closed = true;
    } else if (m->opcode == 1) {
      Json j = Json::parse(m->text(), nullptr, false);
      if (j.is_object() && j.value("t", "") == "error") error = j.value("message", "");
    } else if (m->opcode == 2) {
      auto h = view::web::readFrameHeader(m->data.data());
      ws.sendText(Json{{"t", "ack"}, {"frame", h.frame}}.dump());
      ++frames;
      ws.sendText(Json{{"t", "wheel"}, {"x", 0.5}, {"y", 0.5}, {"steps", frames % 2 ? 1 : -1}}.dump());
    }
  }
  auto closedAt = std::chrono::steady_clock::now();
  EXPECT_GT(frames, 0) << "the device was lost before the first frame";
  EXPECT_TRUE(closed) << "the connection stayed open";
  EXPECT_NE(error.find("device was lost"), std::string::npos) << "the page was told: '" << error << "'";
  // Exit within 5 s of the close (polled; the bound is the requirement itself).
  while (server->alive() && std::chrono::steady_clock::now() - closedAt < std::chrono::seconds(5))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_FALSE(server->alive()) << "still running 5 s after closing its clients";
  EXPECT_EQ(server->stop(), 1);
  std::string err = server->stderrText();
  EXPECT_NE(err.find("device was lost"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  auto exit = server->exitEvent();
  ASSERT_TRUE(exit);
  EXPECT_EQ((*exit).value("error", false), true);
}

} // namespace
} // namespace pointrast::test
