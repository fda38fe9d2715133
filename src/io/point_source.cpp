#include "io/point_source.h"

#include "io/format_table.h"
#include "io/io_util.h"

namespace pointrast::io {

std::unique_ptr<PointSource> openPointSource(const std::filesystem::path& path) {
  const FormatInfo* format = detectFormat(path);
  if (format && format->openPoints) return format->openPoints(path);
  detail::fail(path, std::string(format ? "a " + std::string(format->name) + " file" : "this input") +
                         " cannot be read as a stream of pieces");
}

} // namespace pointrast::io
