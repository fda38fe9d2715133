#include "view/web/request_rules.h"

namespace pointrast::view::web {

namespace {

// WebSocket close codes (RFC 6455, 7.4.1).
constexpr uint16_t kCloseProtocol = 1002;
constexpr uint16_t kCloseUnsupported = 1003;
constexpr uint16_t kCloseNotUtf8 = 1007;
constexpr uint16_t kCloseTooBig = 1009;

FrameVerdict refuse(uint16_t code, std::string why) {
  return {FrameAction::Refuse, code, std::move(why)};
}

} // namespace

std::optional<HttpRefusal> gateRequest(const AccessPolicy& policy, const HttpRequest& request,
                                       bool stopping) {
  Verdict verdict = checkRequest(policy, request.facts);
  // The page's script and style hold no data. A page in another site's frame (a notebook) gets no cookie
  // with its requests, so they load without the token; the WebSocket still needs it.
  if (verdict == Verdict::NoToken && !request.facts.websocket && request.publicPageFile)
    verdict = Verdict::Allow;
  if (stopping) return HttpRefusal{503, "the server is shutting down"};
  if (!decodePath(request.path) || hasControlCharacter(request.facts.queryToken) ||
      hasControlCharacter(request.facts.cookieToken) || hasControlCharacter(request.facts.bearerToken))
    return HttpRefusal{400,
                       "a control character (such as %00) or a malformed escape in the path or the token"};
  if (verdict != Verdict::Allow) return HttpRefusal{403, verdictReason(verdict)};
  if (request.method != "GET" && request.method != "HEAD") return HttpRefusal{405, "only GET and HEAD"};
  return std::nullopt;
}

FrameVerdict checkFrame(int bits, std::string_view payload) {
  int opcode = bits & 0x0F;
  bool final = (bits & 0x80) != 0;
  if (bits & 0x70) return refuse(kCloseProtocol, "reserved bits set (no extension was agreed)");
  if ((opcode > kOpBinary && opcode < kOpClose) || opcode > kOpPong)
    return refuse(kCloseProtocol, "unknown opcode " + std::to_string(opcode));
  bool control = opcode >= kOpClose;
  if (control && (!final || payload.size() > 125))
    return refuse(kCloseProtocol, "a control frame fragmented or longer than 125 bytes");
  if (opcode == kOpClose) {
    if (payload.size() == 1 || (payload.size() > 2 && !isUtf8(payload.substr(2))))
      return refuse(payload.size() == 1 ? kCloseProtocol : kCloseNotUtf8, "a malformed close frame");
    return {FrameAction::Close, 0, ""};
  }
  if (opcode == kOpPing || opcode == kOpPong) return {FrameAction::Ignore, 0, ""};
  if (opcode == kOpContinuation)
    return refuse(kCloseProtocol, "a continuation frame without a message to continue");
  return {FrameAction::Message, 0, ""};
}

std::optional<FrameVerdict> checkMessage(int bits, std::string_view payload, size_t maxBytes) {
  if (payload.size() > maxBytes) return refuse(kCloseTooBig, "message longer than the allowed bytes");
  if ((bits & 0x0F) != kOpText || !(bits & 0x80))
    return refuse(kCloseUnsupported, "only whole text messages are accepted");
  if (!isUtf8(payload)) return refuse(kCloseNotUtf8, "a text message that is not UTF-8");
  return std::nullopt;
}

} // namespace pointrast::view::web
