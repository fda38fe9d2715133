// What `pointrast serve` answers before anything is drawn, as pure functions of what the HTTP server
// parsed: the gate every request and WebSocket upgrade passes (access rules, path, method) and the rules
// of RFC 6455 for each WebSocket frame and message. No socket is needed to test or fuzz them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "view/web/access.h"

namespace pointrast::view::web {

// The facts of one request that the gate judges; the tokens as decoded from the query, the cookie and the
// Authorization header (empty when absent).
struct HttpRequest {
  std::string_view method, path; // path as sent, still percent-encoded
  RequestFacts facts;
  bool publicPageFile = false; // one of the page's script or style files (no data in them), public when the
                               // viewer may be framed by other sites (serve --frame-ancestors)
};

struct HttpRefusal {
  int status = 0;  // 400, 403, 405 or 503
  std::string why; // one sentence, never quoting the request
};

// Nothing when the request may go on to the page or the WebSocket; otherwise the status and why.
std::optional<HttpRefusal> gateRequest(const AccessPolicy& policy, const HttpRequest& request, bool stopping);

// WebSocket opcodes (RFC 6455, 5.2).
constexpr int kOpContinuation = 0x0, kOpText = 0x1, kOpBinary = 0x2, kOpClose = 0x8, kOpPing = 0x9,
              kOpPong = 0xA;

enum class FrameAction {
  Message, // a data frame: on to checkMessage
  Ignore,  // a ping or pong (the HTTP server answers pings)
  Close,   // a well-formed close frame: answer it
  Refuse,  // fail the connection with `code`
};

struct FrameVerdict {
  FrameAction action = FrameAction::Message;
  uint16_t code = 0; // the close status (RFC 6455, 7.4.1) when refused
  std::string why;
};

// The rules RFC 6455 (5.2, 5.5, 8.1) asks of a server for one frame whose first byte is `bits` (FIN, RSV1-3,
// opcode): no reserved bits without an extension, no unknown opcode, no control frame fragmented or over
// 125 bytes, a close frame's reason in UTF-8, no continuation without a message to continue (the server
// takes only single-frame messages).
FrameVerdict checkFrame(int bits, std::string_view payload);

// For a frame checkFrame let through as a message: only whole text messages of at most `maxBytes` bytes in
// UTF-8 are accepted. Nothing when accepted.
std::optional<FrameVerdict> checkMessage(int bits, std::string_view payload, size_t maxBytes);

} // namespace pointrast::view::web
