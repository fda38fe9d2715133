// libFuzzer target for the browser viewer's WebSocket rules (view/web/request_rules.h): the input is a run
// of frames as the HTTP server hands them to `pointrast serve` (first byte: FIN, RSV1-3, opcode; then a
// two-byte little-endian length, at most 2 KiB, and the payload), judged frame by frame until one fails
// the connection. Besides crashes and undefined behaviour it traps on a broken promise: a refusal with a
// close code other than RFC 6455's for the case, a close frame let through whose reason is not UTF-8, a
// text message accepted that a reference UTF-8 decoder (RFC 3629, written here) rejects, or the reverse.
//
// Seeds: with WS_FUZZ_SEEDS=DIR set, the target first writes the frames a page sends.
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

constexpr size_t kMaxBytes = 1024; // the server's kMaxMessageBytes

std::string frame(uint8_t bits, std::string_view payload) {
  std::string f(1, char(bits));
  f += char(payload.size() & 0xFF);
  f += char(payload.size() >> 8);
  return f + std::string(payload);
}

void writeSeeds(const std::string& dir) {
  const std::vector<std::string> seeds = {
      frame(0x81, R"({"t":"resize","w":640,"h":480})") + frame(0x81, R"({"t":"ack","frame":1})"),
      frame(0x81, R"({"t":"move","x":0.5,"y":0.25})") + frame(0x89, "ping") + frame(0x8A, ""),
      frame(0x88, std::string("\x03\xe8", 2) + "bye \xc3\xa9"),
      frame(0x01, "{\"t\":") + frame(0x80, "\"key\"}"),
      frame(0x82, std::string(4, '\0')) + frame(0xC1, "x"),
      frame(0x81, "\xed\xa0\x80 \xf4\x90\x80\x80 \xc0\xaf"),
  };
  for (size_t i = 0; i < seeds.size(); ++i)
    std::ofstream(dir + "/seed" + std::to_string(i), std::ios::binary) << seeds[i];
}

// RFC 3629, section 4's syntax: the reference the server's check is compared with.
bool referenceUtf8(std::string_view s) {
  auto in = [&](size_t i, int lo, int hi) {
    return i < s.size() && uint8_t(s[i]) >= lo && uint8_t(s[i]) <= hi;
  };
  for (size_t i = 0; i < s.size();) {
    uint8_t c = uint8_t(s[i]);
    if (c <= 0x7F) {
      i += 1;
    } else if (c >= 0xC2 && c <= 0xDF && in(i + 1, 0x80, 0xBF)) {
      i += 2;
    } else if (c == 0xE0 && in(i + 1, 0xA0, 0xBF) && in(i + 2, 0x80, 0xBF)) {
      i += 3;
    } else if (((c >= 0xE1 && c <= 0xEC) || c == 0xEE || c == 0xEF) && in(i + 1, 0x80, 0xBF) &&
               in(i + 2, 0x80, 0xBF)) {
      i += 3;
    } else if (c == 0xED && in(i + 1, 0x80, 0x9F) && in(i + 2, 0x80, 0xBF)) {
      i += 3;
    } else if (c == 0xF0 && in(i + 1, 0x90, 0xBF) && in(i + 2, 0x80, 0xBF) && in(i + 3, 0x80, 0xBF)) {
      i += 4;
    } else if (c >= 0xF1 && c <= 0xF3 && in(i + 1, 0x80, 0xBF) && in(i + 2, 0x80, 0xBF) &&
               in(i + 3, 0x80, 0xBF)) {
      i += 4;
    } else if (c == 0xF4 && in(i + 1, 0x80, 0x8F) && in(i + 2, 0x80, 0xBF) && in(i + 3, 0x80, 0xBF)) {
      i += 4;
    } else {
      return false;
    }
  }
  return true;
}

void check(bool promise) {
  if (!promise) __builtin_trap();
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* seeds = std::getenv("WS_FUZZ_SEEDS"); seeds && *seeds) writeSeeds(seeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view input(reinterpret_cast<const char*>(data), size);
  check(isUtf8(input) == referenceUtf8(input));
  for (size_t at = 0; at + 3 <= input.size();) {
    int bits = uint8_t(input[at]);
    size_t length = (uint8_t(input[at + 1]) | size_t(uint8_t(input[at + 2])) << 8) & 0x7FF;
    at += 3;
    std::string_view payload = input.substr(at, length);
    at += payload.size();
    int opcode = bits & 0x0F;
    FrameVerdict v = checkFrame(bits, payload);
    switch (v.action) {
    case FrameAction::Refuse:
      check(v.code == 1002 || (v.code == 1007 && opcode == kOpClose));
      check(!v.why.empty());
      return 0; // the connection is failed: nothing after it is read
    case FrameAction::Close:
      check(opcode == kOpClose && (bits & 0x70) == 0 && (bits & 0x80) && payload.size() != 1 &&
            payload.size() <= 125 && (payload.size() < 2 || referenceUtf8(payload.substr(2))));
      return 0;
    case FrameAction::Ignore:
      check(opcode == kOpPing || opcode == kOpPong);
      break;
    case FrameAction::Message: {
      check((bits & 0x70) == 0 && (opcode == kOpText || opcode == kOpBinary));
      std::optional<FrameVerdict> m = checkMessage(bits, payload, kMaxBytes);
      bool whole = opcode == kOpText && (bits & 0x80);
      if (!m) {
        check(whole && payload.size() <= kMaxBytes && referenceUtf8(payload));
      } else {
        check(m->action == FrameAction::Refuse);
        if (payload.size() > kMaxBytes)
          check(m->code == 1009);
        else if (!whole)
          check(m->code == 1003);
        else
          check(m->code == 1007 && !referenceUtf8(payload));
        return 0;
      }
      break;
    }
    }
  }
  return 0;
}
