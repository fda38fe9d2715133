#include "view/web/export.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <unistd.h>
#include <vector>

#include "base/error.h"
#include "io/format_table.h"
#include "io/writer.h"

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
    throw InputError("export: " + what + " takes finite numbers, got '" + text.substr(0, 40) + "'");
  return v;
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

PointFilter parseExportQuery(std::string_view query) {
  PointFilter f;
  bool mode = false;
  for (std::string_view pair : split(query, '&')) {
    if (pair.empty()) continue;
    const size_t eq = pair.find('=');
    const std::string_view key = pair.substr(0, eq);
    const std::optional<std::string> decoded =
        decodeQueryValue(eq == std::string_view::npos ? std::string_view() : pair.substr(eq + 1));
    if (!decoded) throw InputError("export: a broken %-escape in the query");
    const std::string_view value = *decoded;
    if (key == "token") continue; // the access rules read it
    if (key == "box") {
      std::vector<std::string_view> items = split(value, ',');
      if (items.size() != 6 || !f.boxes.empty()) throw InputError("export: box takes x0,y0,z0,x1,y1,z1 once");
      ClipBox b;
      for (int i = 0; i < 3; ++i) {
        b.min[i] = finiteNumber(items[size_t(i)], "box");
        b.max[i] = finiteNumber(items[size_t(i) + 3], "box");
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
        const double c = finiteNumber(item, "classes");
        if (c < 0 || c > 255 || c != std::floor(c)) throw InputError("export: classes take 0 to 255");
        f.classes->set(size_t(c));
      }
    } else {
      throw InputError("export: unknown parameter '" + std::string(key.substr(0, 32)) + "'");
    }
  }
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

} // namespace pointrast::view::web
