#include "cli_util.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "base/error.h"

namespace pointrast::app {

namespace {

std::vector<double> parseNumbers(std::string_view text, std::string_view option, size_t count) {
  std::vector<double> values;
  std::string s(text);
  size_t at = 0;
  while (values.size() < count + 1) {
    size_t comma = s.find(',', at);
    std::string item = s.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    char* end = nullptr;
    double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(v)) break;
    values.push_back(v);
    if (comma == std::string::npos) {
      if (values.size() == count) return values;
      break;
    }
    at = comma + 1;
  }
  throw InputError(std::string(option) + " expects " + std::to_string(count) +
                   " comma-separated numbers, got '" + std::string(text) + "'");
}

} // namespace

glm::dvec3 parseVec3(std::string_view text, std::string_view option) {
  std::vector<double> v = parseNumbers(text, option, 3);
  return {v[0], v[1], v[2]};
}

std::pair<double, double> parseRange(std::string_view text, std::string_view option) {
  std::vector<double> v = parseNumbers(text, option, 2);
  if (!(v[0] < v[1]))
    throw InputError(std::string(option) + " expects lo,hi with lo < hi, got '" + std::string(text) + "'");
  return {v[0], v[1]};
}

uint32_t parseRgb(std::string_view text, std::string_view option) {
  std::vector<double> v = parseNumbers(text, option, 3);
  for (double c : v)
    if (c < 0 || c > 255 || c != std::floor(c))
      throw InputError(std::string(option) + " expects three integers 0..255, got '" + std::string(text) +
                       "'");
  return uint32_t(v[0]) | uint32_t(v[1]) << 8 | uint32_t(v[2]) << 16 | 0xFF000000u;
}

uint64_t parseCount(std::string_view text, std::string_view option) {
  std::string s(text);
  double scale = 1;
  if (!s.empty()) {
    switch (s.back()) {
    case 'k':
    case 'K':
      scale = 1e3;
      break;
    case 'M':
      scale = 1e6;
      break;
    case 'G':
    case 'B':
      scale = 1e9;
      break;
    default:
      break;
    }
    if (scale != 1) s.pop_back();
  }
  char* end = nullptr;
  double v = std::strtod(s.c_str(), &end);
  double n = v * scale;
  if (s.empty() || *end != '\0' || !std::isfinite(n) || n < 0 || n > 1e15 || n != std::floor(n))
    throw InputError(std::string(option) + " expects a count such as 1000000, 2.5M or 1.2G, got '" +
                     std::string(text) + "'");
  return uint64_t(n);
}

std::string jsonText(const nlohmann::json& j) {
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

uint64_t parseBytes(std::string_view text, std::string_view option) {
  std::string s(text);
  for (const char* suffix : {"iB", "B"})
    if (s.size() > std::string(suffix).size() && s.ends_with(suffix)) {
      s.resize(s.size() - std::string(suffix).size());
      break;
    }
  double scale = 1;
  if (!s.empty()) {
    const std::string units = "kKMGT";
    const size_t unit = units.find(s.back());
    if (unit != std::string::npos) {
      scale = std::ldexp(1.0, 10 * int(unit == 0 ? 1 : unit));
      s.pop_back();
    }
  }
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  const double n = std::floor(v * scale);
  if (s.empty() || *end != '\0' || !std::isfinite(n) || n < 0 || n > 1e18)
    throw InputError(std::string(option) + " expects a size such as 8G, 512M or 1.5GiB, got '" +
                     std::string(text) + "'");
  return uint64_t(n);
}

uint64_t imageHash(const uint32_t* pixels, uint64_t count) {
  uint64_t h = 0xcbf29ce484222325ull;
  auto bytes = reinterpret_cast<const unsigned char*>(pixels);
  for (uint64_t i = 0; i < count * 4; ++i)
    h = (h ^ bytes[i]) * 0x100000001b3ull;
  return h;
}

// The command as typed, for the report (the Linux kernel keeps it NUL-separated).
std::string commandLine(std::string_view fallback) {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string raw{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::string line;
  size_t at = 0;
  bool first = true;
  while (at < raw.size()) {
    size_t end = raw.find('\0', at);
    std::string arg = raw.substr(at, end == std::string::npos ? std::string::npos : end - at);
    if (first) arg = std::filesystem::path(arg).filename().string();
    if (arg.empty() || arg.find_first_of(" \t'\"$\\") != std::string::npos) {
      std::string quoted = "'";
      for (char c : arg)
        quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
      arg = quoted + "'";
    }
    line += (first ? "" : " ") + arg;
    first = false;
    at = end == std::string::npos ? raw.size() : end + 1;
  }
  return line.empty() ? std::string(fallback) : line;
}

} // namespace pointrast::app
