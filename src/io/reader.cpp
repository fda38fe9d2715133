// Reading whole clouds through the format table (io/format_table.h).
#include "io/reader.h"

#include "io/format_table.h"
#include "io/formats.h"
#include "io/io_util.h"
#include "io/point_source.h"

namespace pointrast::io {

using namespace detail;

namespace {

// The row that reads `path` as a whole cloud; InputError (from the row's refusal, or naming every
// format) when there is none.
const FormatInfo& cloudFormat(const std::filesystem::path& path) {
  const FormatInfo* format = detectFormat(path);
  if (format && format->read) return *format;
  if (format && format->refuse) format->refuse(path);
  if (format) fail(path, std::string("a ") + format->name + " file cannot be read as a point cloud");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail(path, "a folder, not a point cloud file");
  if (InputFile(path).size() == 0) fail(path, "the file is empty");
  fail(path, unrecognisedFormatText());
}

} // namespace

PointCloud readCloud(const std::filesystem::path& path, const ReadOptions& options) {
  return cloudFormat(path).read(path, options);
}

FileInfo probeFile(const std::filesystem::path& path) {
  const FormatInfo& format = cloudFormat(path);
  FileInfo info = format.probe(path);
  info.format = &format;
  return info;
}

std::optional<uint64_t> statedPointCount(const std::filesystem::path& path) {
  const FormatInfo& format = cloudFormat(path);
  // A streaming source opens from the header (LAS, LAZ, COPC: counts checked against the file there).
  if (format.openPoints) return format.openPoints(path)->info().pointCount;
  if (format.read == readPly) return statedCountPly(path);
  return std::nullopt; // text, or a format whose count only reading tells
}

} // namespace pointrast::io
