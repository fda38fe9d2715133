// SPIR-V modules compiled from shaders/ at build time and embedded in the binary (cmake/shaders.cmake).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

namespace pointrast::gpu {

struct EmbeddedShader {
  std::string_view name; // "raster_atomicmin.comp": file name without .glsl
  std::span<const uint32_t> words;
};

std::span<const EmbeddedShader> embeddedShaders();

// Finds a module by name; throws std::logic_error if it is missing (a build mistake, not a user error).
std::span<const uint32_t> findShader(std::string_view name);

} // namespace pointrast::gpu
