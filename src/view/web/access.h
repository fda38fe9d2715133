// Who may talk to the browser viewer. Bound to a loopback address (the default), only this machine's users
// reach it, and the checks are those a browser needs against other web sites: the Host header must name
// the loopback (a DNS-rebinding site's name does not) and a WebSocket's Origin, when sent, must be a
// loopback origin (another site's page may not open our socket). Bound anywhere else, every request and
// WebSocket upgrade must carry the access token: in the query (?token=), in the cookie the page gets with
// it, or as "Authorization: Bearer". Pure functions of the request's facts, tested without a network.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace pointrast::view::web {

// 127.0.0.1, ::1 and localhost are local; every other address (127.0.0.2 included) needs a token.
bool isLocalBind(std::string_view address);
// 128 bits from the kernel's random source, as 32 hex digits.
std::string generateToken();
// Comparison in time independent of where the strings differ.
bool tokenMatches(std::string_view given, std::string_view expected);
// A Host header (or an Origin's host) naming the loopback: localhost, 127.x.x.x or [::1], any port.
bool isLoopbackHost(std::string_view host);
// Whether `text` holds a byte below 0x20 or 0x7F (NUL included): refused in paths and tokens, where a C
// string would end early or a log line break.
bool hasControlCharacter(std::string_view text);
// The percent-decoded path of a request; nothing when an escape is malformed or decodes to a control
// character ("%00", "%0a").
std::optional<std::string> decodePath(std::string_view raw);
// Whether `text` is well-formed UTF-8 (RFC 3629: no overlong forms, no surrogates, nothing past U+10FFFF).
bool isUtf8(std::string_view text);

struct AccessPolicy {
  std::string token; // required when not empty
  uint16_t port = 0;
  // The cookie that carries the token after the page was opened with ?token=: one per port, so that two
  // servers on one host keep theirs.
  std::string cookieName() const { return "pointrast_" + std::to_string(port); }
};

struct RequestFacts {
  std::string_view host, origin; // headers, empty when absent
  std::string_view queryToken, cookieToken, bearerToken;
  bool websocket = false;
};

enum class Verdict { Allow, NoToken, WrongToken, ForeignHost, ForeignOrigin };

Verdict checkRequest(const AccessPolicy& policy, const RequestFacts& request);
// One sentence for the 403 page and the log.
const char* verdictReason(Verdict verdict);

// Messages a client may send: a bucket of kMessageBurst refilled at kMessagesPerSecond. A page sends at
// most one pointer move and one acknowledgement per displayed frame (330 a second on a 165 Hz display),
// below this; a client over it is cut off.
constexpr double kMessagesPerSecond = 400;
constexpr double kMessageBurst = 400;

class MessageBudget {
public:
  // Takes one message at time `now` (seconds); false when the budget is spent.
  bool take(double now);

private:
  double tokens_ = kMessageBurst;
  double last_ = -1;
};

} // namespace pointrast::view::web
