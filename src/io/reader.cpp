// Format detection and dispatch. Content decides first (magic bytes), the extension only for text
// formats, which have no magic.
#include "io/reader.h"

#include "io/formats.h"
#include "io/io_util.h"
#include "io/las_format.h"

namespace pointrast::io {

using namespace detail;

const char* formatName(Format format) {
  switch (format) {
  case Format::Las:
    return "LAS";
  case Format::Laz:
    return "LAZ";
  case Format::Ply:
    return "PLY";
  case Format::Xyz:
    return "XYZ";
  case Format::Mmpld:
    return "MMPLD";
  case Format::Unknown:
    break;
  }
  return "unknown";
}

Format detectFormat(const std::filesystem::path& path) {
  InputFile file(path);
  uint8_t magic[8] = {};
  size_t got = file.readSome(0, magic, sizeof magic);
  if (got >= 4 && std::memcmp(magic, "LASF", 4) == 0)
    return lasLooksCompressed(file) ? Format::Laz : Format::Las;
  // "ply" ends its own line (PLY header, first line); trailing spaces and CR LF are tolerated.
  if (got >= 4 && std::memcmp(magic, "ply", 3) == 0 &&
      (magic[3] == '\n' || magic[3] == '\r' || magic[3] == ' ' || magic[3] == '\t'))
    return Format::Ply;
  if (got >= 6 && std::memcmp(magic, "MMPLD\0", 6) == 0) return Format::Mmpld;
  std::string ext = lowerExtension(path);
  if (ext == ".xyz" || ext == ".txt" || ext == ".csv" || ext == ".pts") return Format::Xyz;
  return Format::Unknown;
}

namespace {

[[noreturn]] void failUnreadable(const std::filesystem::path& path, Format format) {
  if (format == Format::Laz) failCompressed(path);
  if (format == Format::Mmpld)
    fail(path, "an MMPLD file holds particles (spheres), not a point cloud; `pointrast info` and the sphere "
               "renderers read it");
  InputFile file(path); // a missing or unreadable file reports that instead
  if (file.size() == 0) fail(path, "the file is empty");
  fail(path, "not a LAS, LAZ, PLY, XYZ/CSV/PTS or MMPLD file (unrecognised content and extension)");
}

} // namespace

PointCloud readCloud(const std::filesystem::path& path, const ReadOptions& options) {
  Format format = detectFormat(path);
  switch (format) {
  case Format::Las:
    return readLas(path, options);
  case Format::Ply:
    return readPly(path, options);
  case Format::Xyz:
    return readXyz(path, options);
  default:
    failUnreadable(path, format);
  }
}

FileInfo probeFile(const std::filesystem::path& path) {
  Format format = detectFormat(path);
  switch (format) {
  case Format::Las:
    return probeLas(path);
  case Format::Ply:
    return probePly(path);
  case Format::Xyz:
    return probeXyz(path);
  default:
    failUnreadable(path, format);
  }
}

std::optional<uint64_t> statedPointCount(const std::filesystem::path& path) {
  Format format = detectFormat(path);
  switch (format) {
  case Format::Las: {
    InputFile file(path);
    return readLasHeader(file).pointCount; // checked against the file's size there
  }
  case Format::Ply:
    return statedCountPly(path);
  case Format::Xyz:
    return std::nullopt;
  default:
    failUnreadable(path, format);
  }
}

} // namespace pointrast::io
