// libFuzzer target for the browser viewer's request gate (view/web/request_rules.h, access.h): the input
// is an HTTP request head (request line, then "Name: value" lines), split the way the HTTP server hands it
// over, and judged as `pointrast serve` judges it, under a policy without and with a token. Besides crashes
// and undefined behaviour it traps on a broken promise: a decoded path with a control character, a refusal
// with a status other than 400, 403, 405 or 503 or with a control character in its sentence, a request let
// through without the token where one is required, a token that does not match itself
// (an empty one never matches).
//
// Seeds: with HTTP_FUZZ_SEEDS=DIR set, the target first writes requests a page and its WebSocket send.
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "view/web/access.h"
#include "view/web/request_rules.h"

namespace {

using namespace pointrast::view::web;

void writeSeeds(const std::string& dir) {
  const std::vector<std::string> seeds = {
      "GET / HTTP/1.1\r\nHost: localhost:8080\r\n\r\n",
      "GET /?token=0123456789abcdef0123456789abcdef HTTP/1.1\r\nHost: 10.0.0.1:8080\r\n\r\n",
      "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nUpgrade: websocket\r\nOrigin: http://localhost:8080\r\n"
      "Cookie: pointrast_8080=0123456789abcdef0123456789abcdef\r\n\r\n",
      "GET /app.js HTTP/1.1\r\nHost: example.org\r\n\r\n",
      "HEAD /healthz HTTP/1.1\r\nHost: [::1]:8080\r\nAuthorization: Bearer "
      "0123456789abcdef0123456789abcdef\r\n\r\n",
      "POST /%00x%zz HTTP/1.1\r\nHost: evil.example\r\nOrigin: https://evil.example\r\n\r\n",
  };
  for (size_t i = 0; i < seeds.size(); ++i)
    std::ofstream(dir + "/seed" + std::to_string(i), std::ios::binary) << seeds[i];
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

bool equalsIgnoringCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if ((a[i] | 0x20) != (b[i] | 0x20)) return false;
  return true;
}

// The value of `name=` in a query or cookie string (separated by `separator`), percent-decoded as the
// HTTP server decodes it; a malformed escape leaves it as sent.
std::string valueOf(std::string_view text, std::string_view name, char separator) {
  size_t at = 0;
  while (at <= text.size()) {
    size_t end = text.find(separator, at);
    std::string_view part =
        trim(text.substr(at, end == std::string_view::npos ? std::string_view::npos : end - at));
    if (part.size() > name.size() && part.substr(0, name.size()) == name && part[name.size()] == '=') {
      std::string_view raw = part.substr(name.size() + 1);
      std::string decoded;
      for (size_t i = 0; i < raw.size(); ++i) {
        auto hex = [](char c) {
          return c >= '0' && c <= '9'                     ? c - '0'
                 : (c | 0x20) >= 'a' && (c | 0x20) <= 'f' ? (c | 0x20) - 'a' + 10
                                                          : -1;
        };
        if (raw[i] == '%' && i + 2 < raw.size() && hex(raw[i + 1]) >= 0 && hex(raw[i + 2]) >= 0) {
          decoded += char(hex(raw[i + 1]) * 16 + hex(raw[i + 2]));
          i += 2;
        } else {
          decoded += raw[i] == '+' ? ' ' : raw[i];
        }
      }
      return decoded;
    }
    if (end == std::string_view::npos) break;
    at = end + 1;
  }
  return {};
}

void check(bool promise) {
  if (!promise) __builtin_trap();
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* seeds = std::getenv("HTTP_FUZZ_SEEDS"); seeds && *seeds) writeSeeds(seeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string_view> lines;
  for (size_t at = 0; at < input.size();) {
    size_t end = input.find('\n', at);
    if (end == std::string_view::npos) end = input.size();
    lines.push_back(trim(input.substr(at, end - at)));
    at = end + 1;
  }
  if (lines.empty()) return 0;
  std::string_view requestLine = lines[0];
  size_t space = requestLine.find(' ');
  std::string_view method = requestLine.substr(0, space);
  std::string_view target =
      space == std::string_view::npos ? std::string_view{} : requestLine.substr(space + 1);
  target = target.substr(0, target.find(' '));
  size_t question = target.find('?');
  std::string_view path = target.substr(0, question);
  std::string_view query =
      question == std::string_view::npos ? std::string_view{} : target.substr(question + 1);

  std::string_view host, origin, upgrade, cookie, authorization;
  for (size_t i = 1; i < lines.size(); ++i) {
    size_t colon = lines[i].find(':');
    if (colon == std::string_view::npos) continue;
    std::string_view name = trim(lines[i].substr(0, colon)), value = trim(lines[i].substr(colon + 1));
    if (equalsIgnoringCase(name, "Host")) host = value;
    if (equalsIgnoringCase(name, "Origin")) origin = value;
    if (equalsIgnoringCase(name, "Upgrade")) upgrade = value;
    if (equalsIgnoringCase(name, "Cookie")) cookie = value;
    if (equalsIgnoringCase(name, "Authorization")) authorization = value;
  }
  for (const std::string& token : {std::string(), std::string("0123456789abcdef0123456789abcdef")}) {
    AccessPolicy policy{token, 8080};
    std::string queryToken = valueOf(query, "token", '&');
    std::string cookieToken = valueOf(cookie, policy.cookieName(), ';');
    std::string_view bearer =
        authorization.substr(0, 7) == "Bearer " ? authorization.substr(7) : std::string_view{};
    HttpRequest request{method, path,
                        RequestFacts{host, origin, queryToken, cookieToken, bearer, !upgrade.empty()},
                        path == "/app.js" || path == "/style.css"};
    std::optional<HttpRefusal> refusal = gateRequest(policy, request, false);
    if (refusal) {
      check(refusal->status == 400 || refusal->status == 403 || refusal->status == 405 ||
            refusal->status == 503);
      check(!refusal->why.empty() && !hasControlCharacter(refusal->why));
    }
    // Bound elsewhere, a request with no token at all reaches nothing but the page's public files.
    if (!token.empty() && queryToken.empty() && cookieToken.empty() && bearer.empty() &&
        !(request.publicPageFile && !request.facts.websocket))
      check(refusal.has_value());
    check(gateRequest(policy, request, true).value_or(HttpRefusal{}).status == 503);
  }
  if (auto decoded = decodePath(path)) check(!hasControlCharacter(*decoded));
  check(tokenMatches(host, host) == !host.empty()); // an empty token never matches, not even itself
  check(!tokenMatches(host, std::string(host) + "x"));
  isLoopbackHost(host);
  isUtf8(input);
  return 0;
}
