// Who may reach the browser viewer: loopback rules without a token, the token everywhere else.
#include "view/web/access.h"

#include <gtest/gtest.h>

namespace pointrast::view::web {
namespace {

TEST(Access, OnlyTheLoopbackNamesAreLocalBinds) {
  EXPECT_TRUE(isLocalBind("127.0.0.1"));
  EXPECT_TRUE(isLocalBind("::1"));
  EXPECT_TRUE(isLocalBind("localhost"));
  EXPECT_FALSE(isLocalBind("127.0.0.2"));
  EXPECT_FALSE(isLocalBind("0.0.0.0"));
  EXPECT_FALSE(isLocalBind("::"));
  EXPECT_FALSE(isLocalBind("192.168.1.5"));
}

TEST(Access, LoopbackHostHeaders) {
  for (const char* host :
       {"localhost", "localhost:8080", "LOCALHOST:1", "127.0.0.1:80", "127.9.8.7", "[::1]:8080", "[::1]"})
    EXPECT_TRUE(isLoopbackHost(host)) << host;
  for (const char* host : {"", "evil.com", "evil.com:8080", "localhost.evil.com", "128.0.0.1", "[::2]:80",
                           "[::1", "[::1]x", "127.0.0.1.nip.io", "0x7f.0.0.1"})
    EXPECT_FALSE(isLoopbackHost(host)) << host;
}

TEST(Access, TokensAreRandomAndComparedWhole) {
  std::string a = generateToken(), b = generateToken();
  EXPECT_EQ(a.size(), 32u);
  EXPECT_NE(a, b);
  EXPECT_TRUE(tokenMatches(a, a));
  EXPECT_FALSE(tokenMatches(a.substr(0, 31), a));
  EXPECT_FALSE(tokenMatches(a + "0", a));
  EXPECT_FALSE(tokenMatches("", ""));
}

TEST(Access, WithATokenEveryRequestMustCarryIt) {
  AccessPolicy policy;
  policy.token = "0123456789abcdef0123456789abcdef";
  RequestFacts r;
  r.host = "evil.com"; // the token guards; the host does not matter then
  EXPECT_EQ(checkRequest(policy, r), Verdict::NoToken);
  r.queryToken = "0123456789abcdef0123456789abcdee";
  EXPECT_EQ(checkRequest(policy, r), Verdict::WrongToken);
  r.queryToken = policy.token;
  EXPECT_EQ(checkRequest(policy, r), Verdict::Allow);
  r.queryToken = {};
  r.cookieToken = policy.token;
  EXPECT_EQ(checkRequest(policy, r), Verdict::Allow);
  r.cookieToken = {};
  r.bearerToken = policy.token;
  r.websocket = true;
  EXPECT_EQ(checkRequest(policy, r), Verdict::Allow);
}

// With a token, a browser's WebSocket (it sends Origin) must come from the server's own page: the cookie
// would otherwise let any page the user opens drive the viewer.
TEST(Access, WithATokenAWebSocketFromAnotherPageIsRefused) {
  AccessPolicy policy;
  policy.token = "0123456789abcdef0123";
  RequestFacts r;
  r.host = "10.0.0.5:8080";
  r.cookieToken = policy.token;
  r.websocket = true;
  r.origin = "http://10.0.0.5:8080";
  EXPECT_EQ(checkRequest(policy, r), Verdict::Allow);
  r.origin = "http://evil.example";
  EXPECT_EQ(checkRequest(policy, r), Verdict::ForeignOrigin);
  r.origin = "http://10.0.0.5:8081";
  EXPECT_EQ(checkRequest(policy, r), Verdict::ForeignOrigin);
  r.origin = "null";
  EXPECT_EQ(checkRequest(policy, r), Verdict::ForeignOrigin);
  r.origin = {}; // tools send no Origin
  EXPECT_EQ(checkRequest(policy, r), Verdict::Allow);
  r.origin = "http://evil.example"; // the page itself (no upgrade) is not a cross-site read
  r.websocket = false;
  EXPECT_EQ(checkRequest(policy, r), Verdict::Allow);
}

TEST(Access, WithoutATokenOnlyLoopbackHostsAndOrigins) {
  AccessPolicy policy;
  RequestFacts r;
  r.host = "127.0.0.1:8080";
  EXPECT_EQ(checkRequest(policy, r), Verdict::Allow);
  r.host = "rebound.example:8080"; // a DNS-rebinding page's name
  EXPECT_EQ(checkRequest(policy, r), Verdict::ForeignHost);
  r.host = "localhost:8080";
  r.websocket = true;
  r.origin = "http://localhost:8080";
  EXPECT_EQ(checkRequest(policy, r), Verdict::Allow);
  r.origin = "https://evil.com";
  EXPECT_EQ(checkRequest(policy, r), Verdict::ForeignOrigin);
  r.origin = "null";
  EXPECT_EQ(checkRequest(policy, r), Verdict::ForeignOrigin);
  r.origin = {}; // tools send no Origin
  EXPECT_EQ(checkRequest(policy, r), Verdict::Allow);
}

TEST(Access, TheMessageBudgetRefillsAtItsRate) {
  MessageBudget budget;
  int taken = 0;
  while (budget.take(10.0))
    ++taken;
  EXPECT_EQ(taken, int(kMessageBurst));
  EXPECT_FALSE(budget.take(10.0));
  // One and a half messages' worth of time later: one more (the half is not a message; whole seconds
  // would hide a rate off by rounding).
  EXPECT_TRUE(budget.take(10.0 + 1.5 / kMessagesPerSecond));
  EXPECT_FALSE(budget.take(10.0 + 1.5 / kMessagesPerSecond));
}

} // namespace
} // namespace pointrast::view::web
