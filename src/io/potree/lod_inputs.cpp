#include "io/potree/lod_inputs.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>

#include "io/io_util.h"

namespace pointrast::io::detail {

namespace {

// Quanta kept free at both ends of the int32 range, for rounding.
constexpr double kInt32Low = -2147483648.0 + 64, kInt32High = 2147483647.0 - 64;

bool sameFrame(const PointSourceInfo& a, const PointSourceInfo& b) {
  return a.scale == b.scale && a.offset == b.offset;
}

} // namespace

BuildInputs::BuildInputs(const std::vector<std::filesystem::path>& paths) {
  if (paths.empty()) throw InputError("no input files");
  for (const auto& path : paths) {
    Input input;
    input.source = openPointSource(path);
    inputs_.push_back(std::move(input));
  }
  for (size_t i = 0; i < inputs_.size(); ++i) {
    const PointSource& s = *inputs_[i].source;
    for (size_t p = 0; p < s.pieces().size(); ++p) {
      tasks_.push_back({i, p, s.pieces()[p].count});
      points_ += s.pieces()[p].count;
      fileBytes_ += s.pieceBytes(p);
    }
  }
  chooseFrame();
  chooseTail();
}

void BuildInputs::chooseTail() {
  bool first = true;
  for (const Input& in : inputs_) {
    const TailFormat t = in.source->tailFormat();
    if (!t.attributes.any()) continue;
    if (first) {
      tail_ = t;
      first = false;
      continue;
    }
    bool ok = true;
    tail_.attributes = mergeAttributes(tail_.attributes, t.attributes, ok);
    if (!ok)
      throw InputError(in.source->info().source + ": its extra bytes or scan angle unit differ from " +
                       inputs_.front().source->info().source +
                       "'s; one octree cannot hold the attributes of both");
    if (tail_.lasPointFormat < 0) tail_.lasPointFormat = t.lasPointFormat;
    if (tail_.extraBytesDescriptors.empty()) tail_.extraBytesDescriptors = t.extraBytesDescriptors;
  }
  tail_.layout = attributeLayout(tail_.attributes);
}

void BuildInputs::chooseFrame() {
  const PointSourceInfo& first = inputs_.front().source->info();
  bool allSame = first.scale.x > 0 && first.scale.y > 0 && first.scale.z > 0;
  for (const Input& in : inputs_)
    allSame = allSame && sameFrame(in.source->info(), first);
  scale_ = first.scale;
  offset_ = first.offset;
  if (allSame) return; // every input keeps its integers

  Bounds all;
  scale_ = glm::abs(first.scale);
  for (const Input& in : inputs_) {
    const PointSourceInfo& info = in.source->info();
    scale_ = glm::min(scale_, glm::abs(info.scale));
    if (info.pointCount > 0) all.expand(info.bounds);
  }
  bool coarsened = false;
  for (int a = 0; a < 3 && !all.empty(); ++a) {
    auto fits = [&] {
      return (all.min[a] - offset_[a]) / scale_[a] >= kInt32Low &&
             (all.max[a] - offset_[a]) / scale_[a] <= kInt32High;
    };
    if (fits()) continue;
    // Center the range on the merged bounds, on a multiple of the scale so integer inputs stay integers.
    offset_[a] = std::floor(all.center()[a] / scale_[a]) * scale_[a];
    while (!fits() && scale_[a] < 1e300) {
      scale_[a] *= 2;
      offset_[a] = std::floor(all.center()[a] / scale_[a]) * scale_[a];
      coarsened = true;
    }
  }
  if (coarsened)
    warn(first.source, strFormat("the merged inputs span more than 32-bit integers hold at the finest scale; "
                                 "the octree's scale is %g, %g, %g",
                                 scale_.x, scale_.y, scale_.z));
  for (Input& in : inputs_) {
    const PointSourceInfo& info = in.source->info();
    in.identity = info.scale == scale_ && info.offset == offset_;
    for (int a = 0; a < 3; ++a) {
      in.mul[a] = info.scale[a] / scale_[a];
      in.add[a] = (info.offset[a] - offset_[a]) / scale_[a];
    }
  }
}

RecordFields BuildInputs::fields() const {
  RecordFields f;
  for (const Input& in : inputs_) {
    const RecordFields& g = in.source->info().fields;
    f.color = f.color || g.color;
    f.intensity = f.intensity || g.intensity;
    f.returnNumber = f.returnNumber || g.returnNumber;
    f.classification = f.classification || g.classification;
    f.pointSourceId = f.pointSourceId || g.pointSourceId;
    if (colorsDecided_ && g.color)
      f.colorMax = std::max<uint16_t>(f.colorMax, in.widenColors ? uint16_t(in.colorMax * 257) : in.colorMax);
  }
  return f;
}

std::string BuildInputs::names() const {
  std::string s;
  for (const Input& in : inputs_)
    s += (s.empty() ? "" : ", ") + in.source->info().source;
  return s;
}

void BuildInputs::read(const Task& task, std::vector<PointRecord>& out) const {
  const Input& in = inputs_[task.input];
  in.source->readPiece(task.piece, out);
  convert(in, out);
}

void BuildInputs::read(const Task& task, std::vector<PointRecord>& out, std::vector<uint8_t>& tails) const {
  const Input& in = inputs_[task.input];
  if (tail_.bytes() == 0) {
    in.source->readPiece(task.piece, out);
    tails.clear();
  } else {
    in.source->readPieceTails(task.piece, out, tail_, tails);
  }
  convert(in, out);
}

void BuildInputs::convert(const Input& in, std::vector<PointRecord>& out) const {
  if (!in.identity) {
    for (PointRecord& r : out) {
      int32_t* q[3] = {&r.x, &r.y, &r.z};
      for (int a = 0; a < 3; ++a) {
        const double v = std::nearbyint(double(*q[a]) * in.mul[a] + in.add[a]);
        if (!(v >= -2147483648.0 && v <= 2147483647.0))
          fail(in.source->info().source,
               "a point lies outside the range the merged octree's scale and offset can hold (its header's "
               "bounds do not hold it)");
        *q[a] = static_cast<int32_t>(v);
      }
    }
  }
  if (in.widenColors)
    for (PointRecord& r : out)
      for (uint16_t& c : r.rgb)
        c = static_cast<uint16_t>(c * 257);
}

BuildInputs::Scan BuildInputs::scan(const std::vector<PointRecord>& records) {
  // Plain locals, so the loop keeps them in registers (through the struct it did not).
  int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  uint16_t colorMax = 0;
  for (const PointRecord& r : records) {
    lo[0] = std::min(lo[0], r.x);
    hi[0] = std::max(hi[0], r.x);
    lo[1] = std::min(lo[1], r.y);
    hi[1] = std::max(hi[1], r.y);
    lo[2] = std::min(lo[2], r.z);
    hi[2] = std::max(hi[2], r.z);
    colorMax = std::max(colorMax, std::max(r.rgb[0], std::max(r.rgb[1], r.rgb[2])));
  }
  Scan s;
  for (int a = 0; a < 3; ++a) {
    s.box.min[a] = lo[a];
    s.box.max[a] = hi[a];
  }
  s.colorMax = colorMax;
  return s;
}

bool BuildInputs::decideColors(const std::vector<Scan>& scans) {
  for (size_t t = 0; t < tasks_.size(); ++t) {
    Input& in = inputs_[tasks_[t].input];
    in.colorMax = std::max(in.colorMax, scans[t].colorMax);
  }
  bool any16 = false;
  for (const Input& in : inputs_)
    any16 = any16 || (in.source->info().fields.color && in.colorMax > 255);
  bool widened = false;
  for (Input& in : inputs_) {
    in.widenColors = any16 && in.source->info().fields.color && in.colorMax <= 255 && in.colorMax > 0;
    widened = widened || in.widenColors;
  }
  colorsDecided_ = true;
  return widened;
}

void BuildInputs::widen(const Task& task, std::vector<PointRecord>& records) const {
  if (!inputs_[task.input].widenColors) return;
  for (PointRecord& r : records)
    for (uint16_t& c : r.rgb)
      c = static_cast<uint16_t>(c * 257);
}

void BuildInputs::orTails(const PointRecord* records, const uint8_t* tails, size_t n, uint8_t* mask,
                          bool& returnsDiffer) const {
  const uint32_t bytes = tail_.bytes();
  if (bytes == 0) return;
  // In 64-bit words: `bytes` words span 8 tails, so word k of every such run holds the same tail bytes.
  const size_t total = n * bytes, period = size_t(bytes) * 8, whole = total / period * period;
  std::vector<uint64_t> words(bytes, 0);
  for (size_t at = 0; at < whole; at += period)
    for (uint32_t k = 0; k < bytes; ++k) {
      uint64_t w;
      std::memcpy(&w, tails + at + 8 * size_t(k), 8);
      words[k] |= w;
    }
  for (uint32_t k = 0; k < bytes; ++k)
    for (uint32_t j = 0; j < 8; ++j)
      mask[(8 * k + j) % bytes] |= static_cast<uint8_t>(words[k] >> (8 * j)); // little endian bytes
  for (size_t at = whole; at < total; ++at)
    mask[at % bytes] |= tails[at];
  const int returns = tail_.layout.numberOfReturns;
  if (returns >= 0)
    for (size_t i = 0; i < n && !returnsDiffer; ++i)
      returnsDiffer = tails[i * bytes + size_t(returns)] != records[i].returnNumber;
}

TailFormat BuildInputs::pruneTail(const std::vector<uint8_t>& mask, bool returnsDiffer) {
  const TailFormat before = tail_;
  const AttributeLayout& l = before.layout;
  auto used = [&](int offset, int size) {
    if (offset < 0) return false;
    for (int b = 0; b < size; ++b)
      if (mask[size_t(offset + b)]) return true;
    return false;
  };
  PointAttributes& a = tail_.attributes;
  a.gpsTime = used(l.gpsTime, 8);
  a.scanAngle = used(l.scanAngle, 2);
  a.nir = used(l.nir, 2);
  a.numberOfReturns = l.numberOfReturns >= 0 && returnsDiffer;
  a.flags = used(l.flags, 1);
  a.userData = used(l.userData, 1);
  tail_.layout = attributeLayout(a);
  return before;
}

void BuildInputs::repack(const TailFormat& from, const TailFormat& to, const uint8_t* src, size_t n,
                         uint8_t* dst) {
  struct Move {
    int from, to, size;
  };
  std::vector<Move> moves;
  auto add = [&](int f, int t, int size) {
    if (t >= 0) moves.push_back({f, t, size});
  };
  add(from.layout.gpsTime, to.layout.gpsTime, 8);
  add(from.layout.scanAngle, to.layout.scanAngle, 2);
  add(from.layout.nir, to.layout.nir, 2);
  add(from.layout.numberOfReturns, to.layout.numberOfReturns, 1);
  add(from.layout.flags, to.layout.flags, 1);
  add(from.layout.userData, to.layout.userData, 1);
  add(from.layout.extraBytes, to.layout.extraBytes, to.attributes.extraBytes);
  const size_t f = from.bytes(), t = to.bytes();
  for (size_t i = 0; i < n; ++i)
    for (const Move& m : moves)
      std::memmove(dst + i * t + size_t(m.to), src + i * f + size_t(m.from), size_t(m.size));
}

} // namespace pointrast::io::detail
