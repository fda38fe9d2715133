#include "io/point_source.h"

#include "io/io_util.h"
#include "io/laz_reader.h"
#include "io/reader.h"

namespace pointrast::io {

std::unique_ptr<PointSource> openPointSource(const std::filesystem::path& path) {
  switch (detectFormat(path)) {
  case Format::Laz:
    return openLazSource(path);
  default:
    detail::fail(path, "streaming reads are available for LAZ files only");
  }
}

} // namespace pointrast::io
