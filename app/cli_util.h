// Parsing helpers shared by the subcommands: vectors ("x,y,z"), colors ("r,g,b"), counts ("1.2G").
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

#include <glm/glm.hpp>

namespace pointrast::app {

// "1,2,3" -> dvec3; throws InputError naming the option on anything else.
glm::dvec3 parseVec3(std::string_view text, std::string_view option);
// "lo,hi" with lo < hi -> {lo, hi}; throws InputError naming the option on anything else.
std::pair<double, double> parseRange(std::string_view text, std::string_view option);
// "r,g,b" with 0..255 each -> packed RGBA8, alpha 255.
uint32_t parseRgb(std::string_view text, std::string_view option);
// "1000000", "1e6", "2.5M", "1.2G", "800k" -> count; throws InputError if not a non-negative integer.
uint64_t parseCount(std::string_view text, std::string_view option);

// "8G", "512M", "1.5GiB", "4096" -> bytes (k, M, G, T are powers of 1024; "B" or "iB" may follow); throws
// InputError naming the option on anything else.
uint64_t parseBytes(std::string_view text, std::string_view option);

// 64-bit FNV-1a of the image bytes: lets two renders be compared without keeping both images.
uint64_t imageHash(const uint32_t* pixels, uint64_t count);

} // namespace pointrast::app
