// The input formats as data: one row per format. Detection, reading, `info`, streaming and LOD access
// all go through the rows, and every list of formats (help, the unreadable-file error, the README check)
// is generated from them.
//
// Adding a format is one row in format_table.cpp plus its reader. A row says:
// - how the format is recognised: `detect` looks at the content (rows with one are tried first, in table
//   order, and the first that accepts the input wins, so a row that refines another, COPC before LAZ,
//   comes first), or, when `detect` is null, the input's extension is one of `extensions` (text formats,
//   which have no magic bytes; tried after every content check);
// - what it can be read as, each optional: a whole cloud (`read`, with `probe` for `info`), a streaming
//   PointSource (`openPoints`: pieces that decode on their own, for the octree builder), a level-of-detail
//   NodeSource (`openNodes`: an octree served node by node);
// - why it cannot be read as a cloud when it cannot (`refuse`), e.g. a particle format.
// Inputs may be files or folders (an EPT dataset, a Potree octree): `detect` sees which.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "io/reader.h"

namespace pointrast::lod {
class NodeSource;
}

namespace pointrast::io {

class PointSource;
namespace detail {
class InputFile;
}

// What a detector sees of an input.
struct FormatProbe {
  static constexpr size_t kHeadBytes = 512;
  std::filesystem::path path;
  bool folder = false;                     // a directory (the file fields are then empty)
  std::span<const uint8_t> head;           // the first kHeadBytes bytes of a file (fewer if it is shorter)
  const detail::InputFile* file = nullptr; // the open file, for signatures further in (LAS VLRs)
  std::string extension;                   // lower case, with the dot: ".las"
};

// What the file holds: points (rendered by the point methods) or particles (spheres with radii, drawn by
// the sphere methods through io/particles/particles_io.h).
enum class FormatContent { Points, Particles };

struct FormatInfo {
  const char* name;       // "LAS": `info`'s format, messages, lists
  const char* extensions; // ".las" or ".xyz .txt .csv .pts": for lists, and detection when
                          // `detect` is null; a folder format may name none ("")
  FormatContent content;
  bool (*detect)(const FormatProbe& input); // null: detected by extension alone
  // Each capability is optional (null: the format is not readable that way).
  PointCloud (*read)(const std::filesystem::path& path, const ReadOptions& options);
  FileInfo (*probe)(const std::filesystem::path& path); // header facts for `info`; with `read`
  std::unique_ptr<PointSource> (*openPoints)(const std::filesystem::path& path);
  std::unique_ptr<lod::NodeSource> (*openNodes)(const std::filesystem::path& path);
  // Throws InputError saying why a file of this format cannot be read as a cloud (it must not return);
  // null: a generic line.
  void (*refuse)(const std::filesystem::path& path);
};

std::span<const FormatInfo> formatTable();

// The row that recognises the file or folder, by content first and extension second; nullptr when none
// does. Throws InputError when the input cannot be opened.
const FormatInfo* detectFormat(const std::filesystem::path& path);

// What a list of formats is for.
enum class FormatUse {
  Cloud,     // readable as a whole point cloud (read)
  Particles, // particle files (the sphere methods)
  Octree,    // level-of-detail sources (openNodes)
};
// "LAS, PLY and XYZ (.xyz, .txt, .csv, .pts)": the rows that serve `use`, in table order, for help and
// messages.
std::string formatList(FormatUse use);

// Opens an octree (a row with openNodes) for level-of-detail rendering. Throws InputError naming the
// formats that are octrees when the input is none of them.
std::unique_ptr<lod::NodeSource> openNodeSource(const std::filesystem::path& path);

} // namespace pointrast::io
