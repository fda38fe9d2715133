#include "view/web/access.h"

#include <sys/random.h>

#include <algorithm>
#include <arpa/inet.h>
#include <cctype>
#include <cstdio>
#include <stdexcept>

namespace pointrast::view::web {

bool isLocalBind(std::string_view address) {
  return address == "127.0.0.1" || address == "::1" || address == "localhost";
}

std::string generateToken() {
  unsigned char bytes[16];
  size_t got = 0;
  while (got < sizeof bytes) {
    ssize_t n = getrandom(bytes + got, sizeof bytes - got, 0);
    if (n <= 0) throw std::runtime_error("no random bytes for the access token");
    got += size_t(n);
  }
  std::string token;
  char hex[3];
  for (unsigned char b : bytes) {
    std::snprintf(hex, sizeof hex, "%02x", b);
    token += hex;
  }
  return token;
}

bool tokenMatches(std::string_view given, std::string_view expected) {
  if (given.size() != expected.size() || expected.empty()) return false;
  unsigned char difference = 0;
  for (size_t i = 0; i < expected.size(); ++i)
    difference |= static_cast<unsigned char>(given[i] ^ expected[i]);
  return difference == 0;
}

bool isLoopbackHost(std::string_view host) {
  // Strip the port: "[::1]:8080" -> "::1", "localhost:8080" -> "localhost".
  std::string name;
  if (!host.empty() && host.front() == '[') {
    size_t close = host.find(']');
    if (close == std::string_view::npos) return false;
    name = std::string(host.substr(1, close - 1));
    std::string_view rest = host.substr(close + 1);
    if (!rest.empty() && rest.front() != ':') return false;
  } else {
    name = std::string(host.substr(0, host.find(':')));
  }
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (name == "localhost" || name == "::1") return true;
  in_addr v4{};
  // inet_pton takes only the dotted quad (no "127.1" shorthands a browser would not send anyway).
  return inet_pton(AF_INET, name.c_str(), &v4) == 1 && (ntohl(v4.s_addr) >> 24) == 127;
}

bool hasControlCharacter(std::string_view text) {
  return std::any_of(text.begin(), text.end(), [](char c) {
    auto b = static_cast<unsigned char>(c);
    return b < 0x20 || b == 0x7F;
  });
}

std::optional<std::string> decodePath(std::string_view raw) {
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  std::string path;
  for (size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] != '%') {
      path += raw[i];
      continue;
    }
    if (i + 2 >= raw.size() || hex(raw[i + 1]) < 0 || hex(raw[i + 2]) < 0) return std::nullopt;
    path += char(hex(raw[i + 1]) * 16 + hex(raw[i + 2]));
    i += 2;
  }
  if (hasControlCharacter(path)) return std::nullopt;
  return path;
}

bool isUtf8(std::string_view text) {
  size_t i = 0;
  while (i < text.size()) {
    auto b = static_cast<unsigned char>(text[i]);
    size_t n = b < 0x80 ? 0 : (b >> 5) == 0x6 ? 1 : (b >> 4) == 0xE ? 2 : (b >> 3) == 0x1E ? 3 : 4;
    if (n == 4 || i + n >= text.size()) return false; // a stray continuation byte, or cut short
    uint32_t code = n == 0 ? b : b & (0x3F >> n);
    for (size_t k = 1; k <= n; ++k) {
      auto c = static_cast<unsigned char>(text[i + k]);
      if ((c & 0xC0) != 0x80) return false;
      code = (code << 6) | (c & 0x3F);
    }
    // The shortest form only, no UTF-16 surrogates, at most U+10FFFF.
    static constexpr uint32_t kLeast[] = {0, 0x80, 0x800, 0x10000};
    if (code < kLeast[n] || (code >= 0xD800 && code <= 0xDFFF) || code > 0x10FFFF) return false;
    i += n + 1;
  }
  return true;
}

namespace {

// "http://localhost:8080" -> "localhost:8080"; empty when not an http(s) origin.
std::string_view originHost(std::string_view origin) {
  for (std::string_view scheme : {"http://", "https://"})
    if (origin.substr(0, scheme.size()) == scheme) {
      std::string_view host = origin.substr(scheme.size());
      return host.substr(0, host.find('/'));
    }
  return {};
}

bool sameHost(std::string_view a, std::string_view b) {
  return !a.empty() && a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
  });
}

} // namespace

Verdict checkRequest(const AccessPolicy& policy, const RequestFacts& request) {
  if (!policy.token.empty()) {
    if (request.queryToken.empty() && request.cookieToken.empty() && request.bearerToken.empty())
      return Verdict::NoToken;
    bool matched = false;
    for (std::string_view given : {request.queryToken, request.cookieToken, request.bearerToken})
      matched = matched || tokenMatches(given, policy.token);
    if (!matched) return Verdict::WrongToken;
    // The cookie goes along with a WebSocket that any page opens: an upgrade that a browser made (it
    // says its Origin) must come from this server's own page.
    if (request.websocket && !request.origin.empty() && !sameHost(originHost(request.origin), request.host))
      return Verdict::ForeignOrigin;
    return Verdict::Allow;
  }
  if (!isLoopbackHost(request.host)) return Verdict::ForeignHost;
  if (request.websocket && !request.origin.empty() && !isLoopbackHost(originHost(request.origin)))
    return Verdict::ForeignOrigin;
  return Verdict::Allow;
}

const char* verdictReason(Verdict verdict) {
  switch (verdict) {
  case Verdict::Allow:
    return "allowed";
  case Verdict::NoToken:
    return "this server needs its access token (open the URL it printed, with ?token=)";
  case Verdict::WrongToken:
    return "wrong access token";
  case Verdict::ForeignHost:
    return "this server answers only requests addressed to localhost";
  case Verdict::ForeignOrigin:
    return "WebSocket connections are accepted only from this server's own page";
  }
  return "refused";
}

bool MessageBudget::take(double now) {
  if (last_ >= 0) tokens_ = std::min(kMessageBurst, tokens_ + (now - last_) * kMessagesPerSecond);
  last_ = now;
  if (tokens_ < 1) return false;
  tokens_ -= 1;
  return true;
}

} // namespace pointrast::view::web
