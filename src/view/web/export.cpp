#include "view/web/export.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <tuple>
#include <unistd.h>
#include <vector>

#include "base/error.h"
#include "io/format_table.h"
#include "io/writer.h"
#include "view/profile_tool.h"

namespace pointrast::view::web {

namespace {

std::vector<std::string_view> split(std::string_view text, char separator) {
  std::vector<std::string_view> parts;
  size_t start = 0;
  while (true) {
    const size_t end = text.find(separator, start);
    parts.push_back(text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (end == std::string_view::npos) return parts;
    start = end + 1;
  }
}

// A query value as sent by a page: %XX escapes and '+' for a space decoded; nullopt for a broken escape.
std::optional<std::string> decodeQueryValue(std::string_view text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '+') {
      out += ' ';
    } else if (text[i] == '%') {
      auto hex = [](char c) {
        return c >= '0' && c <= '9'   ? c - '0'
               : c >= 'a' && c <= 'f' ? c - 'a' + 10
               : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                      : -1;
      };
      if (i + 2 >= text.size()) return std::nullopt;
      const int hi = hex(text[i + 1]), lo = hex(text[i + 2]);
      if (hi < 0 || lo < 0) return std::nullopt;
      out += char(hi * 16 + lo);
      i += 2;
    } else {
      out += text[i];
    }
  }
  return out;
}

double finiteNumber(std::string_view item, const std::string& what) {
  const std::string text(item);
  char* end = nullptr;
  errno = 0;
  const double v = text.empty() || text.size() > 40 ? NAN : std::strtod(text.c_str(), &end);
  if (text.empty() || errno != 0 || end != text.c_str() + text.size() || !std::isfinite(v))
    throw InputError(what + " takes finite numbers, got '" + text.substr(0, 40) + "'");
  return v;
}

// "WxH", digits only, each side in [lo, hi]; nullopt for anything else.
std::optional<std::pair<uint32_t, uint32_t>> pictureSize(std::string_view text, uint32_t loW, uint32_t loH,
                                                         uint32_t hi) {
  const size_t x = text.find('x');
  if (x == std::string_view::npos) return std::nullopt;
  auto side = [&](std::string_view digits, uint32_t lo) -> std::optional<uint32_t> {
    if (digits.empty() || digits.size() > 5) return std::nullopt;
    uint32_t v = 0;
    for (char c : digits) {
      if (c < '0' || c > '9') return std::nullopt;
      v = v * 10 + uint32_t(c - '0');
    }
    if (v < lo || v > hi) return std::nullopt;
    return v;
  };
  const auto w = side(text.substr(0, x), loW), h = side(text.substr(x + 1), loH);
  if (!w || !h) return std::nullopt;
  return std::pair{*w, *h};
}

// A RAII temporary folder: removed with everything in it.
struct TemporaryFolder {
  std::filesystem::path path;
  TemporaryFolder() {
    std::string pattern = (std::filesystem::temp_directory_path() / "pointrast-export-XXXXXX").string();
    if (!::mkdtemp(pattern.data()))
      throw InputError(std::string("export: cannot make a temporary folder: ") + std::strerror(errno));
    path = pattern;
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

} // namespace

ExportSource exportSource(const std::string& input) {
  ExportSource s;
  std::error_code ec;
  if (input.empty() || !std::filesystem::exists(input, ec)) {
    s.whyNot =
        "the input is a generated scene, not a file: export writes the points of a LAS, LAZ or COPC file";
    return s;
  }
  const io::FormatInfo* format =
      std::filesystem::is_regular_file(input, ec) ? io::detectFormat(input) : nullptr;
  const std::string name = format ? format->name : "";
  if (name != "LAS" && name != "LAZ" && name != "COPC") {
    s.whyNot = "export writes the points of a LAS, LAZ or COPC file, and " + input + " is " +
               (format ? "a " + name + " file" : "not one") + "; pointrast convert makes one";
    return s;
  }
  s.file = input;
  return s;
}

namespace {
// Calls each(key, value) for the query's parameters, their values %-decoded, leaving out the token (the
// access rules read it). `what` starts the error for a broken escape.
void forEachParameter(std::string_view query, const char* what,
                      const std::function<void(std::string_view, std::string_view)>& each) {
  for (std::string_view pair : split(query, '&')) {
    if (pair.empty()) continue;
    const size_t eq = pair.find('=');
    const std::string_view key = pair.substr(0, eq);
    const std::optional<std::string> decoded =
        decodeQueryValue(eq == std::string_view::npos ? std::string_view() : pair.substr(eq + 1));
    if (!decoded) throw InputError(std::string(what) + ": a broken %-escape in the query");
    if (key != "token") each(key, *decoded);
  }
}
} // namespace

PointFilter parseExportQuery(std::string_view query) {
  PointFilter f;
  bool mode = false;
  forEachParameter(query, "export", [&](std::string_view key, std::string_view value) {
    if (key == "box") {
      std::vector<std::string_view> items = split(value, ',');
      if (items.size() != 6 || !f.boxes.empty()) throw InputError("export: box takes x0,y0,z0,x1,y1,z1 once");
      ClipBox b;
      for (int i = 0; i < 3; ++i) {
        b.min[i] = finiteNumber(items[size_t(i)], "export: box");
        b.max[i] = finiteNumber(items[size_t(i) + 3], "export: box");
      }
      if (!(b.min.x <= b.max.x && b.min.y <= b.max.y && b.min.z <= b.max.z))
        throw InputError("export: the box's first corner must be its minimum, the second its maximum");
      f.boxes.push_back(b);
    } else if (key == "mode") {
      if (value == "inside")
        f.clipMode = ClipMode::Inside;
      else if (value == "outside")
        f.clipMode = ClipMode::Outside;
      else
        throw InputError("export: mode takes inside or outside");
      mode = true;
    } else if (key == "classes") {
      if (f.classes) throw InputError("export: classes given twice");
      f.classes.emplace();
      for (std::string_view item : split(value, ',')) {
        const double c = finiteNumber(item, "export: classes");
        if (c < 0 || c > 255 || c != std::floor(c)) throw InputError("export: classes take 0 to 255");
        f.classes->set(size_t(c));
      }
    } else {
      throw InputError("export: unknown parameter '" + std::string(key.substr(0, 32)) + "'");
    }
  });
  if (mode && f.boxes.empty()) throw InputError("export: mode needs a box");
  return f;
}

uint64_t exportLas(const std::filesystem::path& source, const PointFilter& filter,
                   const std::function<void(const std::filesystem::path&, uint64_t)>& send) {
  TemporaryFolder folder;
  const std::filesystem::path out = folder.path / "export.las";
  io::LasConvertOptions options;
  options.filter = &filter;
  const uint64_t points = io::convertLasFile(source, out, options);
  send(out, points);
  return points;
}

ProfileQuery parseProfileQuery(std::string_view query, ProfileOutput output) {
  ProfileQuery q;
  bool line = false, width = false, size = false;
  forEachParameter(query, "profile", [&](std::string_view key, std::string_view value) {
    if (key == "line") {
      if (line) throw InputError("profile: line given twice");
      q.line.vertices = parseProfileVertices(std::string(value), "profile: line", kMaxProfileVertices);
      line = true;
    } else if (key == "width") {
      if (width) throw InputError("profile: width given twice");
      q.line.width = finiteNumber(value, "profile: width");
      if (!(q.line.width > 0)) throw InputError("profile: width must be a positive length");
      width = true;
    } else if (key == "size" && output == ProfileOutput::Png) {
      if (size) throw InputError("profile: size given twice");
      const auto wh = pictureSize(value, kProfileMinWidth, kProfileMinHeight, kMaxProfilePictureSide);
      if (!wh)
        throw InputError("profile: size takes WxH, " + std::to_string(kProfileMinWidth) + "x" +
                         std::to_string(kProfileMinHeight) + " to " + std::to_string(kMaxProfilePictureSide) +
                         "x" + std::to_string(kMaxProfilePictureSide));
      std::tie(q.width, q.height) = *wh;
      size = true;
    } else {
      throw InputError("profile: unknown parameter '" + std::string(key.substr(0, 32)) + "'");
    }
  });
  if (!line) throw InputError("profile: the line is missing (line=x1,y1,x2,y2[,...])");
  if (!width) throw InputError("profile: the width is missing (width=W)");
  if (output == ProfileOutput::Png && !size)
    throw InputError("profile: the picture's size is missing (size=WxH)");
  if (!(profileLength(q.line) > 0))
    throw InputError("profile: the line has no length (its vertices coincide)");
  return q;
}

uint64_t exportProfile(const std::string& input, const ProfileQuery& query, ProfileOutput output,
                       const std::function<void(const std::filesystem::path&, uint64_t)>& send) {
  std::error_code ec;
  if (input.empty() || !std::filesystem::exists(input, ec))
    throw InputError("profile: the input is a generated scene, not a file: a profile cuts the points of a "
                     "point cloud file or an octree");
  TemporaryFolder folder;
  ProfileRequest request;
  request.input = input;
  request.line = query.line;
  std::filesystem::path out = folder.path;
  switch (output) {
  case ProfileOutput::Png:
    out /= "profile.png";
    request.imageWidth = query.width;
    request.imageHeight = query.height;
    break;
  case ProfileOutput::Las:
    out /= "profile.las";
    request.las = out.string();
    break;
  case ProfileOutput::Csv:
    out /= "profile.csv";
    request.csv = out.string();
    break;
  }
  const ProfileResult result = cutProfile(request);
  if (output == ProfileOutput::Png) io::writePng(out, query.width, query.height, result.pixels.data());
  send(out, result.points);
  return result.points;
}

} // namespace pointrast::view::web
