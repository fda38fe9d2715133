#include "ws_client.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

namespace pointrast::wsclient {

namespace {

double clockSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

int connectTcp(const std::string& host, uint16_t port) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  if (inet_pton(AF_INET, host.c_str(), &address.sin_addr) != 1) return -1;
  int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    const int error = errno; // the caller reports it
    ::close(fd);
    errno = error;
    return -1;
  }
  int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

bool writeAll(int fd, const void* data, size_t size) {
  auto* p = static_cast<const uint8_t*>(data);
  while (size > 0) {
    ssize_t n = ::send(fd, p, size, MSG_NOSIGNAL);
    if (n <= 0) return false;
    p += n;
    size -= size_t(n);
  }
  return true;
}

// Reads into `out` until it holds "\r\n\r\n" (the end of an HTTP head) or the deadline; returns the head's
// length including the blank line, or 0.
size_t readHead(int fd, std::string& out, double deadline) {
  while (true) {
    size_t end = out.find("\r\n\r\n");
    if (end != std::string::npos) return end + 4;
    if (out.size() > 65536) return 0;
    pollfd p{fd, POLLIN, 0};
    int wait = int(std::max(0.0, deadline - clockSeconds()) * 1000);
    if (poll(&p, 1, wait) <= 0) return 0;
    char buffer[4096];
    ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) return 0;
    out.append(buffer, size_t(n));
  }
}

int statusOf(const std::string& head) {
  int status = 0;
  if (std::sscanf(head.c_str(), "HTTP/1.%*d %d", &status) != 1) return 0;
  return status;
}

} // namespace

HttpResponse httpRequest(const std::string& host, uint16_t port, const std::string& target,
                         const std::vector<std::string>& headers, const std::string& method,
                         double timeoutSeconds) {
  HttpResponse r;
  int fd = connectTcp(host, port);
  if (fd < 0) return r;
  std::string request = method + " " + target + " HTTP/1.1\r\nConnection: close\r\n";
  bool hostGiven = false;
  for (const std::string& h : headers) {
    request += h + "\r\n";
    hostGiven = hostGiven || h.rfind("Host:", 0) == 0;
  }
  if (!hostGiven) request += "Host: " + host + ":" + std::to_string(port) + "\r\n";
  request += "\r\n";
  double deadline = clockSeconds() + timeoutSeconds;
  std::string all;
  if (writeAll(fd, request.data(), request.size())) {
    size_t headLength = readHead(fd, all, deadline);
    if (headLength > 0) {
      r.head = all.substr(0, headLength);
      r.status = statusOf(r.head);
      r.body = all.substr(headLength);
      size_t expected = std::string::npos;
      if (size_t at = r.head.find("Content-Length: "); at != std::string::npos)
        expected = std::stoul(r.head.substr(at + 16));
      if (method == "HEAD") expected = 0;
      while (r.body.size() < expected) {
        pollfd p{fd, POLLIN, 0};
        if (poll(&p, 1, int(std::max(0.0, deadline - clockSeconds()) * 1000)) <= 0) break;
        char buffer[4096];
        ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
        if (n <= 0) break;
        r.body.append(buffer, size_t(n));
      }
    }
  }
  ::close(fd);
  return r;
}

Client::~Client() {
  close();
}

void Client::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  closed_ = true;
}

bool Client::connect(const std::string& host, uint16_t port, const std::string& target,
                     const std::vector<std::string>& headers, double timeoutSeconds) {
  close();
  closed_ = false;
  response_ = {};
  buffered_.clear();
  failure_.clear();
  fd_ = connectTcp(host, port);
  if (fd_ < 0) {
    failure_ = std::string("tcp: ") + std::strerror(errno);
    return false;
  }
  // The key is any 16 bytes in base64; the server's accept value is not checked (we are the test).
  std::string request = "GET " + target + " HTTP/1.1\r\nHost: " + host + ":" + std::to_string(port) +
                        "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n";
  for (const std::string& h : headers)
    request += h + "\r\n";
  request += "\r\n";
  if (!writeAll(fd_, request.data(), request.size())) {
    failure_ = std::string("tcp: sending the upgrade: ") + std::strerror(errno);
    close();
    return false;
  }
  std::string all;
  size_t headLength = readHead(fd_, all, clockSeconds() + timeoutSeconds);
  if (headLength == 0) {
    failure_ =
        "no answer to the upgrade (" + std::to_string(all.size()) + " bytes before the connection ended)";
    close();
    return false;
  }
  response_.head = all.substr(0, headLength);
  response_.status = statusOf(response_.head);
  buffered_.assign(all.begin() + long(headLength), all.end());
  if (response_.status != 101) {
    failure_ = "status " + std::to_string(response_.status);
    response_.body = all.substr(headLength);
    close();
    return false;
  }
  return true;
}

bool Client::sendRaw(std::span<const uint8_t> bytes) {
  return fd_ >= 0 && writeAll(fd_, bytes.data(), bytes.size());
}

bool Client::sendFrame(uint8_t firstByte, std::span<const uint8_t> payload, bool masked,
                       std::optional<uint64_t> declaredLength) {
  uint64_t length = declaredLength.value_or(payload.size());
  std::vector<uint8_t> frame;
  frame.push_back(firstByte);
  uint8_t maskBit = masked ? 0x80 : 0;
  if (length < 126) {
    frame.push_back(uint8_t(maskBit | length));
  } else if (length < 65536) {
    frame.push_back(maskBit | 126);
    frame.push_back(uint8_t(length >> 8));
    frame.push_back(uint8_t(length));
  } else {
    frame.push_back(maskBit | 127);
    for (int shift = 56; shift >= 0; shift -= 8)
      frame.push_back(uint8_t(length >> shift));
  }
  uint8_t mask[4] = {0, 0, 0, 0};
  if (masked) {
    maskState_ = maskState_ * 1664525u + 1013904223u;
    std::memcpy(mask, &maskState_, 4);
    frame.insert(frame.end(), mask, mask + 4);
  }
  size_t start = frame.size();
  frame.insert(frame.end(), payload.begin(), payload.end());
  for (size_t i = 0; masked && i < payload.size(); ++i)
    frame[start + i] ^= mask[i % 4];
  return sendRaw(frame);
}

bool Client::sendText(std::string_view text) {
  return sendFrame(0x81, {reinterpret_cast<const uint8_t*>(text.data()), text.size()});
}

bool Client::fill(double deadline) {
  pollfd p{fd_, POLLIN, 0};
  if (poll(&p, 1, int(std::max(0.0, deadline - clockSeconds()) * 1000)) <= 0) return false;
  uint8_t buffer[65536];
  ssize_t r = ::recv(fd_, buffer, sizeof buffer, 0);
  if (r <= 0) {
    closed_ = true;
    return false;
  }
  buffered_.insert(buffered_.end(), buffer, buffer + r);
  return true;
}

// A whole frame at the front of buffered_: its opcode byte, payload and total length; 0 when incomplete.
size_t Client::parseFrame(uint8_t& first, std::vector<uint8_t>& payload) const {
  const std::vector<uint8_t>& b = buffered_;
  if (b.size() < 2) return 0;
  uint64_t length = b[1] & 0x7F;
  size_t at = 2;
  if (length == 126) {
    if (b.size() < 4) return 0;
    length = uint64_t(b[2]) << 8 | b[3];
    at = 4;
  } else if (length == 127) {
    if (b.size() < 10) return 0;
    length = 0;
    for (int i = 0; i < 8; ++i)
      length = length << 8 | b[2 + i];
    at = 10;
  }
  if (length > (1ull << 30) || b.size() - at < length) return 0;
  first = b[0];
  payload.assign(b.begin() + long(at), b.begin() + long(at + length));
  return at + size_t(length);
}

std::optional<Message> Client::receive(double timeoutSeconds) {
  double deadline = clockSeconds() + timeoutSeconds;
  Message message;
  while (fd_ >= 0) {
    uint8_t first = 0;
    std::vector<uint8_t> payload;
    size_t used = parseFrame(first, payload);
    if (used == 0) {
      if (closed_ || !fill(deadline)) return std::nullopt;
      continue;
    }
    buffered_.erase(buffered_.begin(), buffered_.begin() + long(used));
    int opcode = first & 0x0F;
    if (opcode == 9) { // ping: answer, keep waiting
      sendFrame(0x8A, payload);
      continue;
    }
    if (opcode == 10) continue;
    if (opcode != 0) message.opcode = opcode;
    message.data.insert(message.data.end(), payload.begin(), payload.end());
    if (opcode == 8) closed_ = true;
    if (first & 0x80) return message;
  }
  return std::nullopt;
}

} // namespace pointrast::wsclient
