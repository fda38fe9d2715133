// Parsing helpers shared by the subcommands: vectors ("x,y,z"), colors ("r,g,b"), counts ("1.2G").
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace pointrast::app {

// "1,2,3" -> dvec3; throws InputError naming the option on anything else.
glm::dvec3 parseVec3(std::string_view text, std::string_view option);
// "lo,hi" with lo < hi -> {lo, hi}; throws InputError naming the option on anything else.
std::pair<double, double> parseRange(std::string_view text, std::string_view option);
// "r,g,b" with 0..255 each -> packed RGBA8, alpha 255.
uint32_t parseRgb(std::string_view text, std::string_view option);
// "1000000", "1e6", "2.5M", "1.2G", "800k" -> count; throws InputError if not a non-negative integer.
uint64_t parseCount(std::string_view text, std::string_view option);

// One JSON line. Text that is not UTF-8 (a file name in another encoding) is replaced, not refused: the
// result of a finished run is never lost to how a path was spelt.
std::string jsonText(const nlohmann::json& j);

// "8G", "512M", "1.5GiB", "4096" -> bytes (k, M, G, T are powers of 1024; "B" or "iB" may follow); throws
// InputError naming the option on anything else.
uint64_t parseBytes(std::string_view text, std::string_view option);

// 64-bit FNV-1a of the image bytes: lets two renders be compared without keeping both images.
uint64_t imageHash(const uint32_t* pixels, uint64_t count);

// The command as typed (from /proc/self/cmdline; arguments with spaces or quotes quoted for a shell),
// for a report to say how to reproduce it; `fallback` where the kernel does not tell.
std::string commandLine(std::string_view fallback);

} // namespace pointrast::app
