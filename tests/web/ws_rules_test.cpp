// What `pointrast serve` refuses at the protocol level: WebSocket frames RFC 6455 says a server must fail
// the connection on (with the status code it names), control characters in paths and tokens, a client
// over --max-clients (told why in its close frame).
#include <netinet/in.h>
#include <sys/socket.h>

#include <gtest/gtest.h>

#include "serve_harness.h"
#include "view/web/access.h"
#include "ws_client.h"

namespace pointrast::test {
namespace {

using wsclient::Client;
using wsclient::httpRequest;

std::vector<uint8_t> bytesOf(std::string_view text) {
  return {text.begin(), text.end()};
}

struct Close {
  int code = 0; // 0: the connection ended without a close frame, or nothing came
  std::string reason;
};

// Reads until the server's close frame (other messages skipped) or the end of the connection.
Close closeOf(Client& ws, double seconds = 20) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    auto m = ws.receive(std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count());
    if (!m) return {};
    if (m->opcode != 8) continue;
    Close c;
    if (m->data.size() >= 2) c.code = m->data[0] << 8 | m->data[1];
    if (m->data.size() > 2) c.reason.assign(m->data.begin() + 2, m->data.end());
    return c;
  }
  return {};
}

TEST(Access, PathsAndTokensWithControlCharacters) {
  using view::web::decodePath;
  using view::web::hasControlCharacter;
  EXPECT_EQ(decodePath("/app.js").value_or("?"), "/app.js");
  EXPECT_EQ(decodePath("/a%20b%2Fc").value_or("?"), "/a b/c");
  for (const char* bad : {"/index.html%00.js", "/%0a", "/%0D%0AX: y", "/%7f", "/%", "/%4", "/%zz", "/a%g0"})
    EXPECT_FALSE(decodePath(bad)) << bad;
  EXPECT_TRUE(hasControlCharacter(std::string_view("abc\0def", 7)));
  EXPECT_TRUE(hasControlCharacter("a\tb"));
  EXPECT_FALSE(hasControlCharacter("0123456789abcdef-_"));
  EXPECT_FALSE(hasControlCharacter("\xc3\xa9"));
  // A token compare runs over the whole length: a NUL does not end it.
  EXPECT_FALSE(view::web::tokenMatches(std::string_view("abcd\0xyz", 8), "abcd"));
  EXPECT_FALSE(view::web::tokenMatches(std::string_view("abcd\0xyz", 8), std::string_view("abcd\0xyw", 8)));
}

TEST(Access, Utf8IsCheckedByRfc3629) {
  using view::web::isUtf8;
  for (std::string_view good : {"", "plain", "\xc3\xa9t\xc3\xa9", "\xe2\x82\xac", "\xf0\x9f\x98\x80",
                                "\xf4\x8f\xbf\xbf", "\xed\x9f\xbf", "\xee\x80\x80"})
    EXPECT_TRUE(isUtf8(good)) << good;
  for (std::string_view bad : {"\xc3\x28", "\x80", "\xbf", "\xc0\xaf", "\xe0\x80\xaf", "\xf0\x80\x80\xaf",
                               "\xed\xa0\x80", "\xf4\x90\x80\x80", "\xf8\x88\x80\x80\x80", "\xff", "\xe2\x82",
                               "ab\xc3"})
    EXPECT_FALSE(isUtf8(bad)) << testing::PrintToString(std::string(bad));
}

// One connection per frame; each must end with the server's close frame and the RFC's status code. Frames
// civetweb fails or answers on its own (a declared length past 2 GiB, pings) are covered elsewhere.
TEST(ServeRules, FramesTheRfcForbidsFailTheConnectionWithItsCode) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen());
  ASSERT_TRUE(server.listening()) << server.stderrText();
  const std::string move = R"({"t":"move","x":0.5,"y":0.5})";
  struct Case {
    const char* what;
    uint8_t first;
    std::vector<uint8_t> payload;
    int code;
  };
  std::vector<uint8_t> longClose = {0x03, 0xE8};
  longClose.resize(126, 'x');
  const std::vector<Case> cases = {
      {"RSV1 without an extension", 0xC1, bytesOf(move), 1002},
      {"RSV2", 0xA1, bytesOf(move), 1002},
      {"RSV3", 0x91, bytesOf(move), 1002},
      {"data opcode 3", 0x83, bytesOf(move), 1002},
      {"data opcode 7", 0x87, {}, 1002},
      {"control opcode 0xB", 0x8B, {}, 1002},
      {"control opcode 0xF", 0x8F, {}, 1002},
      {"a fragmented close", 0x08, {0x03, 0xE8}, 1002},
      {"a close of 126 bytes", 0x88, longClose, 1002},
      {"a close of 1 byte", 0x88, {0x03}, 1002},
      {"a close whose reason is not UTF-8", 0x88, {0x03, 0xE8, 0xC3, 0x28}, 1007},
      {"a continuation with nothing to continue", 0x80, bytesOf(move), 1002},
      {"text that is not UTF-8", 0x81, {'"', 0xC3, 0x28, '"'}, 1007},
      {"text with an overlong '/'", 0x81, {'"', 0xC0, 0xAF, '"'}, 1007},
      {"text with a UTF-16 surrogate", 0x81, {'"', 0xED, 0xA0, 0x80, '"'}, 1007},
  };
  for (const Case& c : cases) {
    Client ws;
    ASSERT_TRUE(ws.connect("127.0.0.1", server.port(), "/ws")) << c.what;
    ASSERT_TRUE(ws.sendFrame(c.first, c.payload)) << c.what;
    Close got = closeOf(ws);
    EXPECT_EQ(got.code, c.code) << c.what << ": " << got.reason;
  }
  // A client's close is answered (the closing handshake), and valid messages keep a connection.
  Client polite;
  ASSERT_TRUE(polite.connect("127.0.0.1", server.port(), "/ws"));
  ASSERT_TRUE(polite.sendText(move));
  ASSERT_TRUE(polite.sendFrame(0x88, std::vector<uint8_t>{0x03, 0xE8, 'b', 'y', 'e'}));
  EXPECT_EQ(closeOf(polite).code, 1000);
  EXPECT_EQ(httpRequest("127.0.0.1", server.port(), "/healthz").status, 200);
  EXPECT_EQ(server.stop(), 0) << server.stderrText();
}

// civetweb decodes nothing (its decode_url is off): "%00" reaches the checks instead of ending the path
// early, where "/index.html%00.js" would have been served as "/index.html".
TEST(ServeRules, ControlCharactersInPathsAndTokensAre400) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen() + " --bind 127.0.0.2");
  ASSERT_TRUE(server.listening()) << server.stderrText();
  const std::string url = server.url();
  size_t at = url.find("?token=");
  ASSERT_NE(at, std::string::npos) << url;
  const std::string token = url.substr(at + 7), host = "127.0.0.2";
  const std::string query = "?token=" + token;
  EXPECT_EQ(httpRequest(host, server.port(), "/healthz" + query).status, 200);
  EXPECT_EQ(httpRequest(host, server.port(), "/app.js" + query).status, 200);
  EXPECT_EQ(httpRequest(host, server.port(), "/%61pp.js" + query).status, 200);
  for (const char* path : {"/index.html%00.js", "/healthz%00", "/%00", "/app.js%0a", "/%1b", "/%"}) {
    auto reply = httpRequest(host, server.port(), path + query);
    EXPECT_EQ(reply.status, 400) << path;
    EXPECT_EQ(reply.body.find("<html"), std::string::npos) << path;
  }
  // The token with a NUL and more after it: compared whole, and refused for the NUL.
  for (const std::string& bad : {token + "%00", token + "%00junk", token.substr(0, 16) + "%00" + token.substr(16)})
    EXPECT_EQ(httpRequest(host, server.port(), "/healthz?token=" + bad).status, 400) << bad;
  EXPECT_EQ(httpRequest(host, server.port(), "/healthz?token=" + token + "%0a").status, 400);
  Client ws;
  EXPECT_FALSE(ws.connect(host, server.port(), "/ws?token=" + token + "%00x"));
  EXPECT_EQ(ws.response().status, 400);
  EXPECT_TRUE(ws.connect(host, server.port(), "/ws" + query));
  ws.close();
  EXPECT_EQ(server.stop(), 0) << server.stderrText();
}

// A browser sees nothing of a refused upgrade but the close: the handshake completes and the one frame
// the client gets is a close with 1013 (try again later) and the reason, which the page shows.
TEST(ServeRules, AClientOverMaxClientsGetsOneCloseWithTheReason) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  ServeProcess server(autzen() + " --max-clients 1");
  ASSERT_TRUE(server.listening()) << server.stderrText();
  Client first;
  ASSERT_TRUE(first.connect("127.0.0.1", server.port(), "/ws"));
  auto info = first.receive(60);
  ASSERT_TRUE(info);
  Client second;
  ASSERT_TRUE(second.connect("127.0.0.1", server.port(), "/ws"));
  auto m = second.receive(20);
  ASSERT_TRUE(m);
  ASSERT_EQ(m->opcode, 8) << m->text();
  ASSERT_GE(m->data.size(), 2u);
  EXPECT_EQ(m->data[0] << 8 | m->data[1], 1013);
  EXPECT_EQ(m->text().substr(2), "server full: 1 clients (--max-clients); try again later");
  EXPECT_FALSE(second.receive(2).has_value()); // nothing after the close
  EXPECT_EQ(server.stop(), 0) << server.stderrText();
}

} // namespace
} // namespace pointrast::test
