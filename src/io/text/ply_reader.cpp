// PLY reader (Greg Turk's format as written by CloudCompare, PCL, Meshlab, PDAL): ascii,
// binary_little_endian and binary_big_endian; x, y, z of any scalar type; optional red/green/blue.
//
// Binary files are read in two streaming passes over the vertex data (bounds, then quantization into
// int32 + scale/offset), so memory is the PointCloud itself; ascii files are parsed once into doubles
// (at most 24 B per 6 bytes of text) and quantized from there.
#include <charconv>
#include <optional>
#include <string_view>

#include "base/progress.h"
#include "io/formats.h"
#include "io/io_util.h"

namespace pointrast::io {

using namespace detail;

namespace {

constexpr size_t kMaxHeaderBytes = size_t(16) << 20;
constexpr size_t kMaxTokenBytes = 256;

enum class PlyType : uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

size_t typeSize(PlyType t) {
  switch (t) {
  case PlyType::Int8:
  case PlyType::UInt8:
    return 1;
  case PlyType::Int16:
  case PlyType::UInt16:
    return 2;
  case PlyType::Int32:
  case PlyType::UInt32:
  case PlyType::Float32:
    return 4;
  case PlyType::Float64:
    return 8;
  }
  return 0;
}

bool isFloatType(PlyType t) {
  return t == PlyType::Float32 || t == PlyType::Float64;
}

std::optional<PlyType> parseType(std::string_view s) {
  // The original names and the sized aliases (int8 ... float64) used by VTK, Open3D and others.
  if (s == "char" || s == "int8") return PlyType::Int8;
  if (s == "uchar" || s == "uint8") return PlyType::UInt8;
  if (s == "short" || s == "int16") return PlyType::Int16;
  if (s == "ushort" || s == "uint16") return PlyType::UInt16;
  if (s == "int" || s == "int32") return PlyType::Int32;
  if (s == "uint" || s == "uint32") return PlyType::UInt32;
  if (s == "float" || s == "float32") return PlyType::Float32;
  if (s == "double" || s == "float64") return PlyType::Float64;
  return std::nullopt;
}

const char* typeName(PlyType t) {
  static const char* const kNames[] = {"char", "uchar", "short", "ushort", "int", "uint", "float", "double"};
  return kNames[static_cast<int>(t)];
}

template <class T> T loadAs(const uint8_t* p, bool bigEndian) {
  return bigEndian ? loadBE<T>(p) : loadLE<T>(p);
}

double decode(const uint8_t* p, PlyType t, bool bigEndian) {
  switch (t) {
  case PlyType::Int8:
    return static_cast<int8_t>(p[0]);
  case PlyType::UInt8:
    return p[0];
  case PlyType::Int16:
    return loadAs<int16_t>(p, bigEndian);
  case PlyType::UInt16:
    return loadAs<uint16_t>(p, bigEndian);
  case PlyType::Int32:
    return loadAs<int32_t>(p, bigEndian);
  case PlyType::UInt32:
    return loadAs<uint32_t>(p, bigEndian);
  case PlyType::Float32:
    return loadAs<float>(p, bigEndian);
  case PlyType::Float64:
    return loadAs<double>(p, bigEndian);
  }
  return 0;
}

// A list count as stored in binary: an integer type only (-1 for a float type, refused by the caller, as
// are negative counts of signed types). decode() is exact for every integer type of 32 bits or less.
int64_t decodeCount(const uint8_t* p, PlyType t, bool bigEndian) {
  if (t == PlyType::Float32 || t == PlyType::Float64) return -1;
  return static_cast<int64_t>(decode(p, t, bigEndian));
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32; // the item type for lists
  bool isList = false;
  PlyType countType = PlyType::UInt8;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;

  bool hasLists() const {
    for (const auto& p : properties)
      if (p.isList) return true;
    return false;
  }
  // Bytes per row in binary, for elements without lists.
  uint64_t rowSize() const {
    uint64_t size = 0;
    for (const auto& p : properties)
      size += typeSize(p.type);
    return size;
  }
};

enum class PlyEncoding { Ascii, BinaryLE, BinaryBE };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::Ascii;
  std::string formatLine;
  std::vector<PlyElement> elements;
  std::vector<std::string> comments;
  uint64_t dataOffset = 0;
  size_t vertex = 0;         // index of the vertex element
  int xyz[3] = {-1, -1, -1}; // property indices within the vertex element
  int rgb[3] = {-1, -1, -1}; // -1: no color
  bool hasColor() const { return rgb[0] >= 0; }
  const PlyElement& vertexElement() const { return elements[vertex]; }
};

bool isBlank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

std::vector<std::string_view> splitWords(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && isBlank(line[i]))
      ++i;
    size_t start = i;
    while (i < line.size() && !isBlank(line[i]))
      ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

bool parseUint(std::string_view s, uint64_t& v) {
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && end == s.data() + s.size();
}

// s made safe for a terminal (printable ASCII), cut to max characters.
std::string printable(std::string_view s, size_t max = 40) {
  std::string out(s.substr(0, max));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  return out;
}

// Reads a growing prefix of the file into `text` until it holds the end_header line; returns the offset
// just past that line, where the data starts.
size_t readHeaderText(const InputFile& file, std::string& text) {
  const auto& path = file.path();
  for (size_t want = 4096;; want *= 4) {
    want = static_cast<size_t>(std::min<uint64_t>({want, file.size(), kMaxHeaderBytes}));
    text.resize(want);
    file.readAt(0, text.data(), want);
    size_t at = 0;
    while ((at = text.find("end_header", at)) != std::string::npos) {
      // Must be a line of its own: preceded by a newline, followed by optional blanks and a newline.
      size_t after = at + 10;
      while (after < text.size() && (text[after] == ' ' || text[after] == '\t' || text[after] == '\r'))
        ++after;
      if (at > 0 && text[at - 1] == '\n' && after < text.size() && text[after] == '\n') return after + 1;
      at = after;
    }
    if (want >= file.size() || want >= kMaxHeaderBytes)
      fail(path, want >= kMaxHeaderBytes ? "no end_header line in the first 16 MiB"
                                         : "the PLY header has no end_header line (file truncated?)");
  }
}

// One header line split into words; bad() refuses the file, naming the line by its number.
struct HeaderLine {
  const std::filesystem::path& path;
  size_t number;
  std::string_view text;
  std::vector<std::string_view> words;

  [[noreturn]] void bad(const std::string& what) const {
    fail(path, strFormat("line %zu of the PLY header: %s", number, what.c_str()));
  }
};

// The text of a comment or obj_info line after its keyword, trimmed and made printable.
std::string commentText(const HeaderLine& l) {
  const std::string_view key = l.words[0], line = l.text;
  size_t start = line.find(key) + key.size();
  while (start < line.size() && isBlank(line[start]))
    ++start;
  std::string_view rest = line.substr(start);
  while (!rest.empty() && isBlank(rest.back()))
    rest.remove_suffix(1);
  return printable(rest, 200) + (rest.size() > 200 ? "..." : "");
}

void parseFormat(const HeaderLine& l, PlyHeader& h) {
  const auto& words = l.words;
  if (words[1] == "ascii")
    h.encoding = PlyEncoding::Ascii;
  else if (words[1] == "binary_little_endian")
    h.encoding = PlyEncoding::BinaryLE;
  else if (words[1] == "binary_big_endian")
    h.encoding = PlyEncoding::BinaryBE;
  else
    l.bad("unknown encoding '" + printable(words[1]) + "'");
  h.formatLine = std::string(words[1]) + " " + printable(words[2]);
}

PlyElement parseElement(const HeaderLine& l) {
  PlyElement e;
  if (l.words.size() != 3 || !parseUint(l.words[2], e.count)) l.bad("expected 'element <name> <count>'");
  e.name = printable(l.words[1]);
  return e;
}

PlyProperty parseProperty(const HeaderLine& l) {
  const auto& words = l.words;
  PlyProperty p;
  if (words.size() == 5 && words[1] == "list") {
    auto countType = parseType(words[2]);
    auto itemType = parseType(words[3]);
    if (!countType || !itemType || isFloatType(*countType))
      l.bad("bad list property types '" + printable(words[2]) + " " + printable(words[3]) + "'");
    p.isList = true;
    p.countType = *countType;
    p.type = *itemType;
    p.name = printable(words[4]);
  } else if (words.size() == 3) {
    auto type = parseType(words[1]);
    if (!type) l.bad("unknown property type '" + printable(words[1]) + "'");
    p.type = *type;
    p.name = printable(words[2]);
  } else {
    l.bad("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
  }
  return p;
}

// Parses the header lines in `all` (which ends with the end_header line) into h's encoding, comments and
// elements.
void parseHeaderLines(const std::filesystem::path& path, std::string_view all, PlyHeader& h) {
  bool haveFormat = false;
  size_t lineNo = 0;
  size_t pos = 0;
  while (pos < all.size()) {
    size_t nl = all.find('\n', pos);
    std::string_view text = all.substr(pos, nl - pos);
    pos = nl + 1;
    const HeaderLine l{path, ++lineNo, text, splitWords(text)};
    if (lineNo == 1) {
      if (l.words.size() != 1 || l.words[0] != "ply") l.bad("expected 'ply'");
      continue;
    }
    if (l.words.empty()) continue;
    std::string_view key = l.words[0];
    if (key == "comment" || key == "obj_info") {
      if (h.comments.size() < 16) h.comments.push_back(commentText(l));
    } else if (key == "format") {
      if (haveFormat || l.words.size() != 3) l.bad("expected one 'format <encoding> 1.0' line");
      parseFormat(l, h);
      haveFormat = true;
    } else if (key == "element") {
      h.elements.push_back(parseElement(l));
    } else if (key == "property") {
      if (h.elements.empty()) l.bad("property before any element");
      h.elements.back().properties.push_back(parseProperty(l));
    } else if (key == "end_header") {
      break;
    } else {
      l.bad("unknown keyword '" + printable(key) + "'");
    }
  }
  if (!haveFormat) fail(path, "the PLY header has no format line");
}

// Finds the vertex element and, within it, the x, y, z properties and the color ones if all three are there.
void findVertexProperties(const std::filesystem::path& path, PlyHeader& h) {
  bool found = false;
  for (size_t i = 0; i < h.elements.size(); ++i)
    if (h.elements[i].name == "vertex") {
      h.vertex = i;
      found = true;
      break;
    }
  if (!found) fail(path, "the PLY file has no vertex element");
  const auto& props = h.vertexElement().properties;
  static const char* const kXyz[3] = {"x", "y", "z"};
  static const char* const kRgb[3][3] = {
      {"red", "r", "diffuse_red"}, {"green", "g", "diffuse_green"}, {"blue", "b", "diffuse_blue"}};
  for (size_t i = 0; i < props.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      if (props[i].name == kXyz[a] && h.xyz[a] < 0) {
        if (props[i].isList) fail(path, strFormat("vertex property %s is a list, not a number", kXyz[a]));
        h.xyz[a] = static_cast<int>(i);
      }
      for (const char* name : kRgb[a])
        if (props[i].name == name && h.rgb[a] < 0 && !props[i].isList) h.rgb[a] = static_cast<int>(i);
    }
  }
  if (h.xyz[0] < 0 || h.xyz[1] < 0 || h.xyz[2] < 0)
    fail(path, "the vertex element lacks an x, y or z property");
  if (h.rgb[0] < 0 || h.rgb[1] < 0 || h.rgb[2] < 0) h.rgb[0] = h.rgb[1] = h.rgb[2] = -1;
}

PlyHeader readPlyHeader(const InputFile& file) {
  std::string text;
  PlyHeader h;
  h.dataOffset = readHeaderText(file, text);
  parseHeaderLines(file.path(), std::string_view(text.data(), h.dataOffset), h);
  findVertexProperties(file.path(), h);
  return h;
}

// ---- binary --------------------------------------------------------------------------------------

// Skips one row of an element with lists.
void skipBinaryRow(BufferedReader& in, const PlyElement& e, bool bigEndian,
                   const std::filesystem::path& path) {
  for (const auto& p : e.properties) {
    if (!p.isList) {
      in.skip(typeSize(p.type), "a PLY element");
      continue;
    }
    size_t cs = typeSize(p.countType);
    int64_t n = decodeCount(in.require(cs, "a PLY list count"), p.countType, bigEndian);
    in.consume(cs);
    if (n < 0)
      fail(path,
           strFormat("negative list length %lld in element %s", static_cast<long long>(n), e.name.c_str()));
    in.skip(static_cast<uint64_t>(n) * typeSize(p.type), "a PLY list");
  }
}

void skipBinaryElement(BufferedReader& in, const PlyElement& e, bool bigEndian,
                       const std::filesystem::path& path) {
  if (!e.hasLists()) {
    uint64_t row = e.rowSize();
    if (row && e.count > in.remaining() / row)
      fail(path,
           strFormat("header claims %llu %s elements of %llu bytes but only %llu bytes follow",
                     static_cast<unsigned long long>(e.count), e.name.c_str(),
                     static_cast<unsigned long long>(row), static_cast<unsigned long long>(in.remaining())));
    in.skip(e.count * row, "a PLY element");
    return;
  }
  // Each row with a list takes at least one byte, so this loop ends at the end of the file at worst.
  for (uint64_t i = 0; i < e.count; ++i)
    skipBinaryRow(in, e, bigEndian, path);
}

struct Vertex {
  double xyz[3];
  double rgb[3];
};

// Calls fn(const Vertex&) for every vertex of a binary file, in order.
template <class Fn>
void forEachBinaryVertex(const InputFile& file, const PlyHeader& h, Progress* progress, Fn&& fn) {
  const auto& path = file.path();
  const bool be = h.encoding == PlyEncoding::BinaryBE;
  BufferedReader in(file, h.dataOffset);
  for (size_t i = 0; i < h.vertex; ++i)
    skipBinaryElement(in, h.elements[i], be, path);
  const PlyElement& ve = h.vertexElement();
  const auto& props = ve.properties;
  Vertex v{};
  if (!ve.hasLists()) {
    // Fixed rows: check the whole count up front, then decode batches straight from the window.
    const uint64_t row = ve.rowSize();
    if (ve.count > in.remaining() / row)
      fail(path, strFormat("header claims %llu vertices of %llu bytes but only %llu bytes follow the header",
                           static_cast<unsigned long long>(ve.count), static_cast<unsigned long long>(row),
                           static_cast<unsigned long long>(in.remaining())));
    size_t offsets[6] = {};
    PlyType types[6] = {};
    int slots = h.hasColor() ? 6 : 3;
    for (int s = 0; s < slots; ++s) {
      int prop = s < 3 ? h.xyz[s] : h.rgb[s - 3];
      for (int j = 0; j < prop; ++j)
        offsets[s] += typeSize(props[static_cast<size_t>(j)].type);
      types[s] = props[static_cast<size_t>(prop)].type;
    }
    const uint64_t batchRows = std::max<uint64_t>(1, (uint64_t(4) << 20) / row);
    for (uint64_t done = 0; done < ve.count;) {
      uint64_t rows = std::min(batchRows, ve.count - done);
      const uint8_t* p = in.require(static_cast<size_t>(rows * row), "the PLY vertex data");
      for (uint64_t r = 0; r < rows; ++r, p += row) {
        for (int s = 0; s < 3; ++s)
          v.xyz[s] = decode(p + offsets[s], types[s], be);
        for (int s = 3; s < slots; ++s)
          v.rgb[s - 3] = decode(p + offsets[s], types[s], be);
        fn(v);
      }
      in.consume(static_cast<size_t>(rows * row));
      done += rows;
      if (progress) progress->advance(rows * row);
    }
    return;
  }
  // Rows with lists: walk property by property.
  for (uint64_t i = 0; i < ve.count; ++i) {
    uint64_t before = in.position();
    for (size_t j = 0; j < props.size(); ++j) {
      const auto& p = props[j];
      if (p.isList) {
        size_t cs = typeSize(p.countType);
        int64_t n = decodeCount(in.require(cs, "a PLY list count"), p.countType, be);
        in.consume(cs);
        if (n < 0)
          fail(path, strFormat("negative list length %lld in vertex %llu", static_cast<long long>(n),
                               static_cast<unsigned long long>(i)));
        in.skip(static_cast<uint64_t>(n) * typeSize(p.type), "a PLY list");
        continue;
      }
      size_t size = typeSize(p.type);
      double value = decode(in.require(size, "the PLY vertex data"), p.type, be);
      in.consume(size);
      for (int a = 0; a < 3; ++a) {
        if (static_cast<int>(j) == h.xyz[a]) v.xyz[a] = value;
        if (static_cast<int>(j) == h.rgb[a]) v.rgb[a] = value;
      }
    }
    fn(v);
    if (progress) progress->advance(in.position() - before);
  }
}

// ---- ascii ---------------------------------------------------------------------------------------

// Whitespace-separated tokens with line numbers for messages. A token is valid until the next call.
class Tokens {
public:
  Tokens(BufferedReader& in, const std::filesystem::path& path, uint64_t firstLine)
      : in_(in), path_(path), line_(firstLine) {}
  bool next(std::string_view& token) {
    for (;;) {
      if (in_.fill(1) == 0) return false;
      char c = static_cast<char>(*in_.data());
      if (c == '\n') ++line_;
      if (!(isBlank(c) || c == '\n')) break;
      in_.consume(1);
    }
    size_t avail = in_.fill(kMaxTokenBytes + 1);
    const char* p = reinterpret_cast<const char*>(in_.data());
    size_t len = 0;
    while (len < avail && !isBlank(p[len]) && p[len] != '\n')
      ++len;
    if (len > kMaxTokenBytes)
      fail(path_, strFormat("line %llu: a value longer than %zu characters", line(), kMaxTokenBytes));
    token = std::string_view(p, len);
    in_.consume(len);
    return true;
  }
  unsigned long long line() const { return static_cast<unsigned long long>(line_); }

private:
  BufferedReader& in_;
  const std::filesystem::path& path_;
  uint64_t line_;
};

double parseNumber(std::string_view t, Tokens& tokens, const std::filesystem::path& path) {
  double v = 0;
  const char* b = t.data();
  const char* e = b + t.size();
  if (b != e && *b == '+') ++b;
  auto [end, ec] = std::from_chars(b, e, v);
  if (end != e || (ec != std::errc() && ec != std::errc::result_out_of_range) || b == e)
    fail(path, strFormat("line %llu: '%s' is not a number", tokens.line(), printable(t).c_str()));
  return v;
}

struct Staged {
  std::vector<double> xyz;
  std::vector<float> rgb;
  uint64_t dropped = 0;
  ColorRule colorRule;
};

Staged readAsciiVertices(const InputFile& file, const PlyHeader& h, Progress* progress) {
  const auto& path = file.path();
  BufferedReader in(file, h.dataOffset);
  // The header's line count gives the first data line's number for messages.
  uint64_t headerLines = 0;
  {
    std::string head(static_cast<size_t>(h.dataOffset), '\0');
    file.readAt(0, head.data(), head.size());
    for (char c : head)
      headerLines += c == '\n';
  }
  Tokens tokens(in, path, headerLines + 1);
  std::string_view t;
  auto need = [&](const char* what, uint64_t row, uint64_t count) {
    if (!tokens.next(t))
      fail(path, strFormat("the file ends in %s %llu of %llu", what, static_cast<unsigned long long>(row + 1),
                           static_cast<unsigned long long>(count)));
  };
  for (size_t i = 0; i < h.vertex; ++i) {
    const PlyElement& e = h.elements[i];
    for (uint64_t r = 0; r < e.count; ++r)
      for (const auto& p : e.properties) {
        need(e.name.c_str(), r, e.count);
        if (!p.isList) continue;
        uint64_t n = 0;
        if (!parseUint(t, n))
          fail(path,
               strFormat("line %llu: list length '%s' is not a count", tokens.line(), printable(t).c_str()));
        for (uint64_t k = 0; k < n; ++k)
          need(e.name.c_str(), r, e.count);
      }
  }
  const PlyElement& ve = h.vertexElement();
  Staged s;
  s.colorRule.isFloat = h.hasColor() && isFloatType(ve.properties[static_cast<size_t>(h.rgb[0])].type);
  // Each vertex takes at least two bytes per property ("0 "), which bounds the reservation.
  uint64_t maxRows = in.remaining() / (2 * ve.properties.size()) + 1;
  uint64_t reserve = std::min(ve.count, maxRows);
  s.xyz.reserve(static_cast<size_t>(3 * reserve));
  if (h.hasColor()) s.rgb.reserve(static_cast<size_t>(3 * reserve));
  uint64_t lastPos = in.position();
  for (uint64_t r = 0; r < ve.count; ++r) {
    double xyz[3] = {0, 0, 0}, rgb[3] = {0, 0, 0};
    for (size_t j = 0; j < ve.properties.size(); ++j) {
      const auto& p = ve.properties[j];
      need("vertex", r, ve.count);
      if (p.isList) {
        uint64_t n = 0;
        if (!parseUint(t, n))
          fail(path,
               strFormat("line %llu: list length '%s' is not a count", tokens.line(), printable(t).c_str()));
        for (uint64_t k = 0; k < n; ++k)
          need("vertex", r, ve.count);
        continue;
      }
      int slot = -1;
      for (int a = 0; a < 3; ++a) {
        if (static_cast<int>(j) == h.xyz[a]) slot = a;
        if (static_cast<int>(j) == h.rgb[a]) slot = 3 + a;
      }
      if (slot < 0) continue; // other properties are not even parsed
      double v = parseNumber(t, tokens, path);
      (slot < 3 ? xyz[slot] : rgb[slot - 3]) = v;
    }
    if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) {
      ++s.dropped;
      continue;
    }
    s.xyz.insert(s.xyz.end(), xyz, xyz + 3);
    if (h.hasColor())
      for (double c : rgb) {
        s.rgb.push_back(static_cast<float>(c));
        if (c > s.colorRule.max) s.colorRule.max = c;
      }
    if (progress && (r & 0xFFFF) == 0) {
      progress->advance(in.position() - lastPos);
      lastPos = in.position();
    }
  }
  return s;
}

std::string describeElements(const PlyHeader& h) {
  std::string s;
  for (const auto& e : h.elements)
    s += strFormat(s.empty() ? "%s %llu" : ", %s %llu", e.name.c_str(),
                   static_cast<unsigned long long>(e.count));
  return s;
}

std::string describeVertex(const PlyHeader& h) {
  std::string s;
  for (const auto& p : h.vertexElement().properties) {
    if (!s.empty()) s += ", ";
    if (p.isList)
      s += strFormat("list %s %s %s", typeName(p.countType), typeName(p.type), p.name.c_str());
    else
      s += strFormat("%s %s", typeName(p.type), p.name.c_str());
  }
  return s;
}

void warnDropped(const std::filesystem::path& path, uint64_t dropped) {
  if (dropped)
    warn(path, strFormat("dropped %llu vertices with NaN or infinite coordinates",
                         static_cast<unsigned long long>(dropped)));
}

// Pass 1 of the binary reader and the whole of probe: bounds, colors, non-finite count.
struct BinaryScan {
  Bounds bounds;
  uint64_t finite = 0;
  uint64_t dropped = 0;
  ColorRule colorRule;
};

BinaryScan scanBinary(const InputFile& file, const PlyHeader& h, Progress* progress) {
  BinaryScan scan;
  scan.colorRule.isFloat =
      h.hasColor() && isFloatType(h.vertexElement().properties[static_cast<size_t>(h.rgb[0])].type);
  const bool color = h.hasColor();
  forEachBinaryVertex(file, h, progress, [&](const Vertex& v) {
    if (!std::isfinite(v.xyz[0]) || !std::isfinite(v.xyz[1]) || !std::isfinite(v.xyz[2])) {
      ++scan.dropped;
      return;
    }
    ++scan.finite;
    scan.bounds.expand(glm::dvec3(v.xyz[0], v.xyz[1], v.xyz[2]));
    if (color) scan.colorRule.max = std::max({scan.colorRule.max, v.rgb[0], v.rgb[1], v.rgb[2]});
  });
  return scan;
}

} // namespace

PointCloud readPly(const std::filesystem::path& path, const ReadOptions& options) {
  InputFile file(path);
  const PlyHeader h = readPlyHeader(file);
  PointCloud cloud;
  cloud.source = path.filename().string();
  const bool color = h.hasColor();
  std::optional<Progress> progress;
  const uint64_t dataBytes = file.size() - h.dataOffset;

  if (h.encoding == PlyEncoding::Ascii) {
    if (options.progress) progress.emplace("reading " + path.filename().string(), dataBytes, "B");
    Staged s = readAsciiVertices(file, h, progress ? &*progress : nullptr);
    if (progress) progress->finish();
    warnDropped(path, s.dropped);
    const uint64_t n = s.xyz.size() / 3;
    for (uint64_t i = 0; i < n; ++i)
      cloud.bounds.expand(glm::dvec3(s.xyz[3 * i], s.xyz[3 * i + 1], s.xyz[3 * i + 2]));
    Quantization q = chooseQuantization(path, cloud.bounds);
    cloud.scale = q.scale;
    cloud.offset = q.offset;
    cloud.positions.resize(3 * n);
    for (uint64_t i = 0; i < 3 * n; ++i)
      cloud.positions[i] = quantize(s.xyz[i], q.scale[i % 3], q.offset[i % 3]);
    if (color) {
      cloud.colors.resize(n);
      for (uint64_t i = 0; i < n; ++i)
        cloud.colors[i] =
            packRgba(convertColor(s.rgb[3 * i], s.colorRule), convertColor(s.rgb[3 * i + 1], s.colorRule),
                     convertColor(s.rgb[3 * i + 2], s.colorRule));
    }
  } else {
    if (options.progress) progress.emplace("reading " + path.filename().string(), 2 * dataBytes, "B");
    Progress* p = progress ? &*progress : nullptr;
    BinaryScan scan = scanBinary(file, h, p);
    warnDropped(path, scan.dropped);
    Quantization q = chooseQuantization(path, scan.bounds);
    cloud.scale = q.scale;
    cloud.offset = q.offset;
    // scan.finite <= the vertex count that the file size was checked to hold.
    cloud.positions.resize(3 * scan.finite);
    if (color) cloud.colors.resize(scan.finite);
    uint64_t i = 0;
    forEachBinaryVertex(file, h, p, [&](const Vertex& v) {
      if (!std::isfinite(v.xyz[0]) || !std::isfinite(v.xyz[1]) || !std::isfinite(v.xyz[2])) return;
      if (i == scan.finite) fail(path, "the file changed while it was read");
      for (int a = 0; a < 3; ++a)
        cloud.positions[3 * i + a] = quantize(v.xyz[a], q.scale[a], q.offset[a]);
      if (color)
        cloud.colors[i] =
            packRgba(convertColor(v.rgb[0], scan.colorRule), convertColor(v.rgb[1], scan.colorRule),
                     convertColor(v.rgb[2], scan.colorRule));
      ++i;
    });
    if (progress) progress->finish();
    if (i != scan.finite) fail(path, "the file changed while it was read");
  }
  // Exact bounds of what is stored (quantization moves points by up to scale / 2).
  if (cloud.size() > 0) {
    int32_t qmin[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, qmax[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    for (uint64_t i = 0; i < cloud.positions.size(); ++i) {
      qmin[i % 3] = std::min(qmin[i % 3], cloud.positions[i]);
      qmax[i % 3] = std::max(qmax[i % 3], cloud.positions[i]);
    }
    cloud.bounds = boundsFromQuantized(qmin, qmax, cloud.scale, cloud.offset);
  } else {
    cloud.bounds = Bounds{};
  }
  return cloud;
}

namespace detail {

std::optional<uint64_t> statedCountPly(const std::filesystem::path& path) {
  InputFile file(path);
  const PlyHeader h = readPlyHeader(file);
  // Only a count the data could hold is stated: a vertex takes at least one byte per binary list count
  // and the bytes of each scalar, or in ASCII a character and a separator per property. A larger count is
  // a lie the reader names when it meets the end of the file.
  const PlyElement& vertex = h.vertexElement();
  uint64_t minBytes = 0;
  for (const PlyProperty& p : vertex.properties)
    minBytes += h.encoding == PlyEncoding::Ascii ? 2 : typeSize(p.isList ? p.countType : p.type);
  if (minBytes == 0 || vertex.count > (file.size() - h.dataOffset) / minBytes) return std::nullopt;
  return vertex.count;
}

FileInfo probePly(const std::filesystem::path& path) {
  InputFile file(path);
  const PlyHeader h = readPlyHeader(file);
  FileInfo info;
  info.formatDetail = "PLY " + h.formatLine;
  info.pointCount = h.vertexElement().count;
  info.hasColor = h.hasColor();
  uint64_t dropped = 0;
  if (h.encoding == PlyEncoding::Ascii) {
    Staged s = readAsciiVertices(file, h, nullptr);
    for (size_t i = 0; i + 2 < s.xyz.size(); i += 3)
      info.bounds.expand(glm::dvec3(s.xyz[i], s.xyz[i + 1], s.xyz[i + 2]));
    info.colorBits = info.hasColor ? s.colorRule.bits() : 0;
    dropped = s.dropped;
  } else {
    BinaryScan scan = scanBinary(file, h, nullptr);
    info.bounds = scan.bounds;
    info.colorBits = info.hasColor ? scan.colorRule.bits() : 0;
    dropped = scan.dropped;
  }
  info.extra.emplace_back("elements", describeElements(h));
  info.extra.emplace_back("vertex properties", describeVertex(h));
  // One key (extra is shown as a JSON object too, where keys must be unique).
  std::string comments;
  for (const auto& c : h.comments) {
    if (!comments.empty()) comments += " | ";
    comments += c;
  }
  if (!comments.empty()) info.extra.emplace_back("comments", comments);
  if (dropped) info.extra.emplace_back("dropped (NaN/Inf)", std::to_string(dropped) + " vertices");
  return info;
}

} // namespace detail

} // namespace pointrast::io
