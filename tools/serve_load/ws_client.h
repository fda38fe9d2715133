// A minimal WebSocket client (RFC 6455) over a plain TCP socket, for the load tool and the tests that drive
// `pointrast serve`: it also sends what a browser never would (unmasked, fragmented, oversized or
// reserved frames), which is what the server's hardening is tested with. Blocking, one thread.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pointrast::wsclient {

struct HttpResponse {
  int status = 0; // 0: no HTTP answer (refused, reset, timed out)
  std::string head, body;
};

// One HTTP/1.1 GET (or another method) with extra header lines ("Name: value"; a Host line replaces the
// default one); reads until the server closes or Content-Length bytes arrived.
HttpResponse httpRequest(const std::string& host, uint16_t port, const std::string& target,
                         const std::vector<std::string>& headers = {}, const std::string& method = "GET",
                         double timeoutSeconds = 10);

struct Message {
  int opcode = 0; // 1 text, 2 binary, 8 close
  std::vector<uint8_t> data;
  std::string_view text() const { return {reinterpret_cast<const char*>(data.data()), data.size()}; }
};

class Client {
public:
  Client() = default;
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  // Connects and asks for the upgrade of `target` ("/ws?token=..."). Returns whether the server switched
  // protocols; otherwise response() holds what it said and failure() why the upgrade did not happen.
  bool connect(const std::string& host, uint16_t port, const std::string& target,
               const std::vector<std::string>& headers = {}, double timeoutSeconds = 10);
  const HttpResponse& response() const { return response_; }
  // Why the last connect failed: the TCP connection ("tcp: " and the system's reason), no answer, or the
  // answer's status; empty after a successful one.
  const std::string& failure() const { return failure_; }
  // Whether the last connect failed before the server answered anything (a TCP-level failure).
  bool failedBeforeAnswer() const { return failure_.rfind("tcp: ", 0) == 0; }

  bool sendText(std::string_view text);
  // A raw frame: first byte (FIN, RSV, opcode) as given, payload masked unless `masked` is false, the length
  // field saying `declaredLength` when given (a lie about the payload that follows).
  bool sendFrame(uint8_t firstByte, std::span<const uint8_t> payload, bool masked = true,
                 std::optional<uint64_t> declaredLength = std::nullopt);
  bool sendRaw(std::span<const uint8_t> bytes);

  // The next text, binary or close message within the timeout (pings are answered); nothing on timeout
  // or a closed connection.
  std::optional<Message> receive(double timeoutSeconds);
  bool open() const { return fd_ >= 0 && !closed_; }
  void close();

private:
  bool fill(double deadline);
  size_t parseFrame(uint8_t& first, std::vector<uint8_t>& payload) const;
  int fd_ = -1;
  bool closed_ = false;
  HttpResponse response_;
  std::string failure_;
  std::vector<uint8_t> buffered_; // bytes read past the upgrade response
  uint32_t maskState_ = 0x12345678u;
};

} // namespace pointrast::wsclient
