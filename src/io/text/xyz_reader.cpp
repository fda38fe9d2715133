// Text point reader: XYZ, CSV and Leica PTS.
//
// Values are separated by blanks, commas or semicolons (runs count as one separator). The first data
// line fixes the columns:  3: x y z   4: x y z intensity   6: x y z r g b   7: x y z intensity r g b
// (PTS); any other count of 5 or more reads x y z and ignores the rest. Lines that are blank or start
// with '#' or '//' are skipped, as is a line holding one integer (a PTS point-count line; PTS files
// with several scans repeat it) and one header line of column names before the first data line.
// Colors follow ColorRule (0..255 integers; floats in 0..1 if every value is <= 1 and written with a
// decimal point or exponent; values above 255 are 16-bit). Intensity: PTS stores it signed
// (-2048..2047), so if any value is negative all are shifted by +2048; values are clamped to 0..65535.
#include <charconv>
#include <optional>
#include <string_view>

#include "base/progress.h"
#include "io/formats.h"
#include "io/io_util.h"

namespace pointrast::io {

using namespace detail;

namespace {

constexpr size_t kMaxLineBytes = size_t(1) << 20;

struct XyzData {
  std::vector<double> xyz;
  std::vector<float> rgb;       // 3 per kept point if the columns have color
  std::vector<float> intensity; // 1 per kept point if the columns have intensity
  int columns = 0;
  int intensityColumn = -1;
  int rgbColumn = -1;
  ColorRule colorRule;
  bool negativeIntensity = false;
  bool countLine = false;
  bool headerLine = false;
  uint64_t dropped = 0;
  uint64_t lines = 0;
};

bool isSeparator(char c) {
  return c == ' ' || c == '\t' || c == ',' || c == ';' || c == '\r' || c == '\v' || c == '\f';
}

bool parseDouble(std::string_view t, double& v) {
  const char* b = t.data();
  const char* e = b + t.size();
  if (b != e && *b == '+') ++b;
  if (b == e) return false;
  auto [end, ec] = std::from_chars(b, e, v);
  return end == e && (ec == std::errc() || ec == std::errc::result_out_of_range);
}

bool isInteger(std::string_view t) {
  if (t.empty() || t.size() > 19) return false;
  for (char c : t)
    if (c < '0' || c > '9') return false;
  return true;
}

bool looksFloat(std::string_view t) {
  return t.find_first_of(".eE") != std::string_view::npos;
}

std::string printable(std::string_view s) {
  std::string out(s.substr(0, 40));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  return out;
}

XyzData parseXyz(const InputFile& file, Progress* progress) {
  const auto& path = file.path();
  XyzData d;
  BufferedReader in(file, 0);
  std::vector<std::string_view> tokens;
  uint64_t lineNo = 0;
  uint64_t firstDataLine = 0;
  uint64_t lastReport = 0;
  while (!in.atEnd()) {
    // One line: find '\n' in the window, growing it up to kMaxLineBytes.
    size_t want = 4096;
    size_t len = 0;
    bool newline = false;
    for (;;) {
      size_t avail = in.fill(want);
      const void* nl = std::memchr(in.data(), '\n', avail);
      if (nl) {
        len = static_cast<size_t>(static_cast<const uint8_t*>(nl) - in.data());
        newline = true;
        break;
      }
      if (avail < want) { // the last line, without a newline
        len = avail;
        break;
      }
      if (want >= kMaxLineBytes)
        fail(path, strFormat("line %llu is longer than 1 MiB", static_cast<unsigned long long>(lineNo + 1)));
      want *= 4;
    }
    std::string_view line(reinterpret_cast<const char*>(in.data()), len);
    ++lineNo;
    in.consume(len + (newline ? 1 : 0));
    if (progress && in.position() - lastReport > (1u << 20)) {
      progress->advance(in.position() - lastReport);
      lastReport = in.position();
    }

    tokens.clear();
    for (size_t i = 0; i < line.size();) {
      while (i < line.size() && isSeparator(line[i]))
        ++i;
      size_t start = i;
      while (i < line.size() && !isSeparator(line[i]))
        ++i;
      if (i > start) tokens.push_back(line.substr(start, i - start));
    }
    if (tokens.empty()) continue;
    if (tokens[0][0] == '#' || tokens[0].substr(0, 2) == "//") continue;
    if (tokens.size() == 1 && isInteger(tokens[0])) {
      d.countLine = true;
      continue;
    }
    double first = 0;
    if (d.columns == 0 && !d.headerLine && !parseDouble(tokens[0], first)) {
      d.headerLine = true; // column names
      continue;
    }
    if (d.columns == 0) {
      if (tokens.size() < 3)
        fail(path, strFormat("line %llu has %zu values; expected at least x y z",
                             static_cast<unsigned long long>(lineNo), tokens.size()));
      d.columns = static_cast<int>(tokens.size());
      firstDataLine = lineNo;
      if (d.columns == 4 || d.columns == 7) d.intensityColumn = 3;
      if (d.columns == 6) d.rgbColumn = 3;
      if (d.columns == 7) d.rgbColumn = 4;
    } else if (static_cast<int>(tokens.size()) != d.columns) {
      fail(path, strFormat("line %llu has %zu values, but line %llu has %d",
                           static_cast<unsigned long long>(lineNo), tokens.size(),
                           static_cast<unsigned long long>(firstDataLine), d.columns));
    }
    double v[7];
    auto number = [&](int column) {
      std::string_view t = tokens[static_cast<size_t>(column)];
      if (!parseDouble(t, v[column]))
        fail(path, strFormat("line %llu: '%s' is not a number", static_cast<unsigned long long>(lineNo),
                             printable(t).c_str()));
    };
    for (int c = 0; c < 3; ++c)
      number(c);
    if (d.intensityColumn >= 0) number(d.intensityColumn);
    if (d.rgbColumn >= 0)
      for (int c = 0; c < 3; ++c)
        number(d.rgbColumn + c);
    ++d.lines;
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
      ++d.dropped;
      continue;
    }
    d.xyz.insert(d.xyz.end(), v, v + 3);
    if (d.intensityColumn >= 0) {
      double i = v[d.intensityColumn];
      d.negativeIntensity = d.negativeIntensity || i < 0;
      d.intensity.push_back(static_cast<float>(i));
    }
    if (d.rgbColumn >= 0)
      for (int c = 0; c < 3; ++c) {
        double value = v[d.rgbColumn + c];
        d.rgb.push_back(static_cast<float>(value));
        d.colorRule.max = std::max(d.colorRule.max, value);
        if (looksFloat(tokens[static_cast<size_t>(d.rgbColumn + c)])) d.colorRule.isFloat = true;
      }
  }
  if (progress) progress->advance(in.position() - lastReport);
  if (d.lines == 0) fail(path, "no point lines (x y z ...) in the file");
  if (d.dropped)
    warn(path, strFormat("dropped %llu points with NaN or infinite coordinates",
                         static_cast<unsigned long long>(d.dropped)));
  return d;
}

const char* describeColumns(int columns) {
  switch (columns) {
  case 3:
    return "x y z";
  case 4:
    return "x y z intensity";
  case 6:
    return "x y z r g b";
  case 7:
    return "x y z intensity r g b";
  default:
    return "x y z + ignored columns";
  }
}

} // namespace

PointCloud readXyz(const std::filesystem::path& path, const ReadOptions& options) {
  InputFile file(path);
  std::optional<Progress> progress;
  if (options.progress) progress.emplace("reading " + path.filename().string(), file.size(), "B");
  XyzData d = parseXyz(file, progress ? &*progress : nullptr);
  if (progress) progress->finish();

  PointCloud cloud;
  cloud.source = path.filename().string();
  const uint64_t n = d.xyz.size() / 3;
  Bounds raw;
  for (uint64_t i = 0; i < n; ++i)
    raw.expand(glm::dvec3(d.xyz[3 * i], d.xyz[3 * i + 1], d.xyz[3 * i + 2]));
  Quantization q = chooseQuantization(path, raw);
  cloud.scale = q.scale;
  cloud.offset = q.offset;
  cloud.positions.resize(3 * n);
  int32_t qmin[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, qmax[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  for (uint64_t i = 0; i < 3 * n; ++i) {
    int32_t v = quantize(d.xyz[i], q.scale[i % 3], q.offset[i % 3]);
    cloud.positions[i] = v;
    qmin[i % 3] = std::min(qmin[i % 3], v);
    qmax[i % 3] = std::max(qmax[i % 3], v);
  }
  if (n > 0) cloud.bounds = boundsFromQuantized(qmin, qmax, cloud.scale, cloud.offset);
  if (d.rgbColumn >= 0) {
    cloud.colors.resize(n);
    for (uint64_t i = 0; i < n; ++i)
      cloud.colors[i] =
          packRgba(convertColor(d.rgb[3 * i], d.colorRule), convertColor(d.rgb[3 * i + 1], d.colorRule),
                   convertColor(d.rgb[3 * i + 2], d.colorRule));
  }
  if (d.intensityColumn >= 0 && options.keepAttributes) {
    cloud.intensity.resize(n);
    const double shift = d.negativeIntensity ? 2048.0 : 0.0;
    for (uint64_t i = 0; i < n; ++i) {
      // NaN (which std::clamp passes through and no integer holds) and values below 0 read as 0.
      const double value = std::nearbyint(d.intensity[i] + shift);
      cloud.intensity[i] = value > 0 ? static_cast<uint16_t>(std::min(value, 65535.0)) : 0;
    }
  }
  return cloud;
}

namespace detail {

FileInfo probeXyz(const std::filesystem::path& path) {
  InputFile file(path);
  XyzData d = parseXyz(file, nullptr);
  FileInfo info;
  info.formatDetail = strFormat("XYZ text, %d columns (%s)", d.columns, describeColumns(d.columns));
  info.pointCount = d.xyz.size() / 3;
  for (size_t i = 0; i + 2 < d.xyz.size(); i += 3)
    info.bounds.expand(glm::dvec3(d.xyz[i], d.xyz[i + 1], d.xyz[i + 2]));
  info.hasColor = d.rgbColumn >= 0;
  info.colorBits = info.hasColor ? d.colorRule.bits() : 0;
  info.extra.emplace_back("point lines", std::to_string(d.lines));
  if (d.countLine) info.extra.emplace_back("PTS count line", "yes (skipped)");
  if (d.headerLine) info.extra.emplace_back("header line", "yes (skipped)");
  if (info.hasColor)
    info.extra.emplace_back("color encoding",
                            d.colorRule.isFloat && d.colorRule.max <= 1.0 ? "float 0..1" : "integer");
  if (d.intensityColumn >= 0)
    info.extra.emplace_back("intensity", d.negativeIntensity ? "signed (PTS), stored + 2048" : "unsigned");
  if (d.dropped) info.extra.emplace_back("dropped (NaN/Inf)", std::to_string(d.dropped) + " points");
  return info;
}

} // namespace detail

} // namespace pointrast::io
