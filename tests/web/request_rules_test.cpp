// The gate and the WebSocket rules of `pointrast serve` as pure functions (view/web/request_rules.h), the
// ones the `http` and `ws` fuzz targets drive: each refusal with its status or close code, no socket.
#include <string>

#include <gtest/gtest.h>

#include "view/web/request_rules.h"

namespace pointrast::view::web {
namespace {

HttpRequest get(std::string_view path, std::string_view host = "localhost:8080") {
  return {"GET", path, RequestFacts{host, "", "", "", "", false}, false};
}

int status(const AccessPolicy& policy, const HttpRequest& r, bool stopping = false) {
  auto refusal = gateRequest(policy, r, stopping);
  return refusal ? refusal->status : 0;
}

TEST(RequestRules, TheGateGivesEachRefusalItsStatus) {
  AccessPolicy local{"", 8080};
  EXPECT_EQ(status(local, get("/")), 0);
  EXPECT_EQ(status(local, get("/"), true), 503);
  EXPECT_EQ(status(local, get("/%00")), 400);
  EXPECT_EQ(status(local, get("/%zz")), 400);
  EXPECT_EQ(status(local, get("/", "evil.example")), 403);
  HttpRequest post = get("/");
  post.method = "POST";
  EXPECT_EQ(status(local, post), 405);
  HttpRequest head = get("/healthz");
  head.method = "HEAD";
  EXPECT_EQ(status(local, head), 0);
}

TEST(RequestRules, BoundElsewhereOnlyThePublicFilesLoadWithoutTheToken) {
  const std::string token = "0123456789abcdef0123456789abcdef";
  AccessPolicy remote{token, 8080};
  HttpRequest page = get("/", "10.0.0.1:8080");
  EXPECT_EQ(status(remote, page), 403);
  page.facts.queryToken = token;
  EXPECT_EQ(status(remote, page), 0);
  HttpRequest script = get("/app.js", "10.0.0.1:8080");
  script.publicPageFile = true;
  EXPECT_EQ(status(remote, script), 0);
  script.facts.websocket = true; // the WebSocket always needs it
  EXPECT_EQ(status(remote, script), 403);
  HttpRequest bearer = get("/", "10.0.0.1:8080");
  bearer.facts.bearerToken = token.substr(0, 31) + "\n";
  EXPECT_EQ(status(remote, bearer), 400);
}

TEST(RequestRules, FramesFailTheConnectionWithRfc6455sCodes) {
  EXPECT_EQ(checkFrame(0x81, "{}").action, FrameAction::Message);
  EXPECT_EQ(checkFrame(0x89, "ping").action, FrameAction::Ignore);
  EXPECT_EQ(checkFrame(0x8A, "").action, FrameAction::Ignore);
  EXPECT_EQ(checkFrame(0x88, "").action, FrameAction::Close);
  EXPECT_EQ(checkFrame(0x88, std::string("\x03\xe8", 2) + "bye").action, FrameAction::Close);
  auto refused = [](int bits, std::string_view payload) {
    FrameVerdict v = checkFrame(bits, payload);
    return v.action == FrameAction::Refuse ? v.code : 0;
  };
  EXPECT_EQ(refused(0xC1, "x"), 1002);                            // RSV1 without an extension
  EXPECT_EQ(refused(0x83, ""), 1002);                             // reserved data opcode
  EXPECT_EQ(refused(0x8B, ""), 1002);                             // reserved control opcode
  EXPECT_EQ(refused(0x09, "x"), 1002);                            // fragmented ping
  EXPECT_EQ(refused(0x89, std::string(126, 'x')), 1002);          // control frame over 125 bytes
  EXPECT_EQ(refused(0x88, "\x03"), 1002);                         // a close payload of one byte
  EXPECT_EQ(refused(0x88, std::string("\x03\xe8\xff", 3)), 1007); // a reason that is not UTF-8
  EXPECT_EQ(refused(0x80, "x"), 1002);                            // continuation of nothing
}

TEST(RequestRules, OnlyWholeUtf8TextMessagesWithinTheLimitAreAccepted) {
  EXPECT_FALSE(checkMessage(0x81, R"({"t":"ack","frame":1})", 1024));
  EXPECT_EQ(checkMessage(0x82, "{}", 1024)->code, 1003);
  EXPECT_EQ(checkMessage(0x01, "{}", 1024)->code, 1003);
  EXPECT_EQ(checkMessage(0x81, std::string(1025, ' '), 1024)->code, 1009);
  EXPECT_EQ(checkMessage(0x81, "\xed\xa0\x80", 1024)->code, 1007); // a surrogate
  EXPECT_EQ(checkMessage(0x81, "\xc0\xaf", 1024)->code, 1007);     // an overlong '/'
  EXPECT_FALSE(checkMessage(0x81, "\xf4\x8f\xbf\xbf", 1024));      // U+10FFFF
}

} // namespace
} // namespace pointrast::view::web
