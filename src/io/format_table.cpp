// The format rows, detection and the generated lists.
#include "io/format_table.h"

#include <cstring>
#include <optional>
#include <vector>

#include "cloud/octree.h"
#include "io/formats.h"
#include "io/copc_ept/copc.h"
#include "io/copc_ept/ept.h"
#include "io/io_util.h"
#include "io/las/las_format.h"
#include "io/las/las_source.h"
#include "io/las/laz_reader.h"
#include "io/point_source.h"
#include "io/potree/potree.h"

namespace pointrast::io {

using namespace detail;

namespace {

bool startsWith(const FormatProbe& input, std::string_view magic) {
  return input.head.size() >= magic.size() && std::memcmp(input.head.data(), magic.data(), magic.size()) == 0;
}

bool isLasFile(const FormatProbe& input) {
  return startsWith(input, "LASF") && !lasLooksCompressed(*input.file);
}

bool isLazFile(const FormatProbe& input) {
  return startsWith(input, "LASF") && lasLooksCompressed(*input.file);
}

// COPC: a LAZ file with the COPC info VLR.
bool isCopcFile(const FormatProbe& input) {
  return startsWith(input, "LASF") && hasCopcInfoVlr(*input.file);
}

// An EPT dataset: its folder, or the ept.json in it.
bool isEpt(const FormatProbe& input) {
  return looksLikeEpt(input.path);
}

// "ply" ends its own line (PLY header, first line); trailing spaces and CR LF are tolerated.
bool isPlyFile(const FormatProbe& input) {
  return startsWith(input, "ply") && input.head.size() >= 4 &&
         std::strchr("\n\r \t", char(input.head[3])) != nullptr && input.head[3] != 0;
}

bool isMmpldFile(const FormatProbe& input) {
  return startsWith(input, std::string_view("MMPLD\0", 6));
}

// A Potree 2.0 octree: its folder, or the metadata.json in it.
bool isPotree(const FormatProbe& input) {
  return looksLikePotree(input.path);
}

void refuseParticles(const std::filesystem::path& path) {
  fail(path, "an MMPLD file holds particles (spheres), not a point cloud; `pointrast info` and the sphere "
             "renderers read it");
}

// clang-format off
constexpr FormatInfo kFormats[] = {
  // name    extensions               content                 detect       read     probe     openPoints openNodes refuse
  {"LAS",   ".las",                   FormatContent::Points,    isLasFile,   readLas, probeLas, openLasSource, nullptr, nullptr},
  {"COPC",  ".copc.laz",              FormatContent::Points,    isCopcFile,  readLaz, probeLaz, openLazSource, openCopc, nullptr},
  {"LAZ",   ".laz",                   FormatContent::Points,    isLazFile,   readLaz, probeLaz, openLazSource, nullptr, nullptr},
  {"PLY",   ".ply",                   FormatContent::Points,    isPlyFile,   readPly, probePly, nullptr,   nullptr,  nullptr},
  {"XYZ",   ".xyz .txt .csv .pts",    FormatContent::Points,    nullptr,     readXyz, probeXyz, nullptr,   nullptr,  nullptr},
  {"Potree 2.0", "",                  FormatContent::Points,    isPotree,    readPotree, probePotreeFolder, nullptr, openPotree, nullptr},
  {"EPT",   "",                       FormatContent::Points,    isEpt,       readEpt, probeEpt, nullptr,   openEpt,  nullptr},
  {"MMPLD", ".mmpld",                 FormatContent::Particles, isMmpldFile, nullptr, nullptr,  nullptr,   nullptr,  refuseParticles},
};
// clang-format on

bool hasExtension(const FormatInfo& f, const std::string& extension) {
  if (extension.empty()) return false;
  std::string_view list = f.extensions;
  for (size_t at = 0; at < list.size();) {
    size_t end = list.find(' ', at);
    if (end == std::string_view::npos) end = list.size();
    if (list.substr(at, end - at) == extension) return true;
    at = end + 1;
  }
  return false;
}

bool serves(const FormatInfo& f, FormatUse use) {
  switch (use) {
  case FormatUse::Cloud:
    return f.read != nullptr;
  case FormatUse::Particles:
    return f.content == FormatContent::Particles;
  case FormatUse::Octree:
    return f.openNodes != nullptr;
  }
  return false;
}

// "XYZ (.xyz, .txt, .csv, .pts)" for a row recognised by its extensions alone, else the name.
std::string listedName(const FormatInfo& f) {
  if (f.detect) return f.name;
  std::string extensions = f.extensions;
  for (size_t at = extensions.find(' '); at != std::string::npos; at = extensions.find(' ', at + 2))
    extensions.replace(at, 1, ", ");
  return std::string(f.name) + " (" + extensions + ")";
}

std::string joinNames(const std::vector<std::string>& names, const char* last) {
  std::string text;
  for (size_t i = 0; i < names.size(); ++i)
    text += (i == 0 ? "" : i + 1 == names.size() ? last : ", ") + names[i];
  return text;
}

} // namespace

std::span<const FormatInfo> formatTable() {
  return kFormats;
}

const FormatInfo* detectFormat(const std::filesystem::path& path) {
  FormatProbe input;
  input.path = path;
  input.extension = lowerExtension(path);
  std::error_code ec;
  input.folder = std::filesystem::is_directory(path, ec);
  std::optional<InputFile> file;
  uint8_t head[FormatProbe::kHeadBytes];
  if (!input.folder) {
    file.emplace(path); // a missing or unreadable file says so here
    input.file = &*file;
    input.head = {head, file->readSome(0, head, sizeof head)};
  }
  for (const FormatInfo& f : kFormats)
    if (f.detect && f.detect(input)) return &f;
  if (!input.folder)
    for (const FormatInfo& f : kFormats)
      if (!f.detect && hasExtension(f, input.extension)) return &f;
  return nullptr;
}

std::string formatList(FormatUse use) {
  std::vector<std::string> names;
  for (const FormatInfo& f : kFormats)
    if (serves(f, use)) names.push_back(listedName(f));
  return joinNames(names, " and ");
}

std::string detail::unrecognisedFormatText() {
  std::vector<std::string> names;
  for (const FormatInfo& f : kFormats)
    names.push_back(listedName(f));
  return "not a " + joinNames(names, " or ") + " file (unrecognised content and extension)";
}

std::unique_ptr<lod::NodeSource> openNodeSource(const std::filesystem::path& path) {
  const FormatInfo* f = detectFormat(path);
  if (f && f->openNodes) return f->openNodes(path);
  const std::string octrees = formatList(FormatUse::Octree);
  fail(path, std::string(f ? "a " + std::string(f->name) + " file" : "this input") +
                 " is no level-of-detail octree" +
                 (octrees.empty() ? std::string() : " (" + octrees + " are)"));
}

} // namespace pointrast::io
