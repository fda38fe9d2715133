#include "gpu/shader_registry.h"

#include <stdexcept>
#include <string>

namespace pointrast::gpu {

std::span<const uint32_t> findShader(std::string_view name) {
  for (const EmbeddedShader& s : embeddedShaders())
    if (s.name == name) return s.words;
  // A build mistake (a misspelt name in the method table, a shader file not compiled), never a user
  // error; checked in every build, since benchmarks run Release builds.
  throw std::logic_error("internal error: shader '" + std::string(name) + "' is not embedded in this build");
}

} // namespace pointrast::gpu
