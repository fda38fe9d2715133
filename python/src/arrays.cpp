#include "arrays.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "base/parallel.h"
#include "io/io_util.h"

namespace pointrast::python {

namespace {

std::string dtypeName(const py::array& a) {
  return py::str(a.dtype()).cast<std::string>();
}

// An (N,) array of one of the given dtypes with n elements, or TypeError / ValueError naming `what`.
void checkVector(const py::array& a, const char* what, uint64_t n, bool (*dtypeOk)(const py::dtype&),
                 const char* dtypes) {
  if (!dtypeOk(a.dtype()))
    throw py::type_error(std::string(what) + " must be " + dtypes + ", not " + dtypeName(a));
  if (a.ndim() != 1) throw py::value_error(std::string(what) + " must be one-dimensional (N,)");
  if (uint64_t(a.shape(0)) != n)
    throw py::value_error(std::string(what) + " has " + std::to_string(a.shape(0)) + " values for " +
                          std::to_string(n) + " points");
}

bool isUint8(const py::dtype& d) {
  return d.is(py::dtype::of<uint8_t>());
}
bool isUint16(const py::dtype& d) {
  return d.is(py::dtype::of<uint16_t>());
}
bool isUint8or16(const py::dtype& d) {
  return isUint8(d) || isUint16(d);
}
bool isInt32(const py::dtype& d) {
  return d.is(py::dtype::of<int32_t>());
}

// Element i of a one-dimensional array of T, whatever its stride.
template <typename T> T at(const py::array& a, uint64_t i) {
  return *reinterpret_cast<const T*>(static_cast<const char*>(a.data()) + py::ssize_t(i) * a.strides(0));
}

template <typename T> std::vector<T> copyVector(const py::array& a) {
  std::vector<T> v(a.shape(0));
  for (uint64_t i = 0; i < v.size(); ++i)
    v[i] = at<T>(a, i);
  return v;
}

constexpr uint64_t kBlock = 1 << 20; // points per block of the parallel passes

// The bounds of the rows on every core; the first row that is not finite is the error.
template <typename Src> Bounds rawBounds(const Src* src, uint64_t n) {
  const uint64_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<Bounds> blockBounds(blocks);
  std::vector<uint64_t> firstBad(blocks, UINT64_MAX);
  parallelBlocks(n, kBlock, [&](uint64_t b, uint64_t begin, uint64_t end) {
    Bounds bounds;
    for (uint64_t i = begin; i < end; ++i) {
      const glm::dvec3 p(src[3 * i], src[3 * i + 1], src[3 * i + 2]);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        firstBad[b] = i;
        return;
      }
      bounds.expand(p);
    }
    blockBounds[b] = bounds;
  });
  Bounds raw;
  for (uint64_t b = 0; b < blocks; ++b) {
    if (firstBad[b] != UINT64_MAX)
      throw py::value_error("xyz row " + std::to_string(firstBad[b]) + " is not finite (NaN or infinity)");
    if (!blockBounds[b].empty()) {
      raw.expand(blockBounds[b].min);
      raw.expand(blockBounds[b].max);
    }
  }
  return raw;
}

// Rows of x, y, z quantized as the readers do (io::detail::quantize), four rows at a time: their twelve
// values in three vectors of four lanes, lane l of vector j being axis (4j + l) % 3, so that the divisions
// run four at once; the same arithmetic lane by lane, so the same integers. Where the CPU has AVX2 its clone
// runs (without FMA); the vector types lower to SSE2 pairs elsewhere.
using Double4 = double __attribute__((vector_size(32)));
using Float4 = float __attribute__((vector_size(16)));
using Int4 = int32_t __attribute__((vector_size(16)));

struct RowLanes {
  Double4 scale[3], offset[3];
};

template <typename Src>
inline __attribute__((always_inline)) void quantizeGroups(const Src* src, uint64_t groups, const RowLanes& c,
                                                          int32_t* dst) {
  const Double4 low = {-2147483648.0, -2147483648.0, -2147483648.0, -2147483648.0};
  const Double4 high = {2147483647.0, 2147483647.0, 2147483647.0, 2147483647.0};
  constexpr double kBias = 6755399441055744.0; // as io::detail::quantize: rounds half to even
  const Double4 bias = {kBias, kBias, kBias, kBias};
  for (uint64_t g = 0; g < groups; ++g)
    for (int j = 0; j < 3; ++j) {
      Double4 v;
      if constexpr (std::is_same_v<Src, float>) {
        Float4 f;
        std::memcpy(&f, src + 12 * g + 4 * j, sizeof f);
        v = __builtin_convertvector(f, Double4);
      } else {
        std::memcpy(&v, src + 12 * g + 4 * j, sizeof v);
      }
      Double4 q = (v - c.offset[j]) / c.scale[j];
      q = q > high ? high : q;
      q = q < low ? low : q;
      q = (q + bias) - bias;
      const Int4 r = __builtin_convertvector(q, Int4);
      std::memcpy(dst + 12 * g + 4 * j, &r, sizeof r);
    }
}

__attribute__((target_clones("avx2", "default"))) void quantizeGroupsFloat(const float* src, uint64_t groups,
                                                                           const RowLanes& c, int32_t* dst) {
  quantizeGroups(src, groups, c, dst);
}

__attribute__((target_clones("avx2", "default"))) void
quantizeGroupsDouble(const double* src, uint64_t groups, const RowLanes& c, int32_t* dst) {
  quantizeGroups(src, groups, c, dst);
}

template <typename Src>
void quantizeRows(const Src* src, uint64_t count, const glm::dvec3& scale, const glm::dvec3& offset,
                  int32_t* dst) {
  RowLanes lanes;
  for (int l = 0; l < 12; ++l) {
    lanes.scale[l / 4][l % 4] = scale[l % 3];
    lanes.offset[l / 4][l % 4] = offset[l % 3];
  }
  const uint64_t groups = count / 4;
  if constexpr (std::is_same_v<Src, float>)
    quantizeGroupsFloat(src, groups, lanes, dst);
  else
    quantizeGroupsDouble(src, groups, lanes, dst);
  for (uint64_t i = 4 * groups; i < count; ++i)
    for (int a = 0; a < 3; ++a)
      dst[3 * i + a] = io::detail::quantize(double(src[3 * i + a]), scale[a], offset[a]);
}

const char* checkXyz(const py::array& xyz) {
  const bool f32 = xyz.dtype().is(py::dtype::of<float>());
  const bool f64 = xyz.dtype().is(py::dtype::of<double>());
  if (!f32 && !f64) throw py::type_error("xyz must be float32 or float64, not " + dtypeName(xyz));
  if (xyz.ndim() != 2 || xyz.shape(1) != 3) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < xyz.ndim(); ++d)
      shape += (d ? ", " : "") + std::to_string(xyz.shape(d));
    throw py::value_error("xyz must have the shape (N, 3), not " + shape + (xyz.ndim() == 1 ? ",)" : ")"));
  }
  if (!(xyz.flags() & py::array::c_style))
    throw py::value_error("xyz must be C-contiguous (rows of x, y, z side by side); "
                          "numpy.ascontiguousarray(xyz) makes such a copy");
  return f32 ? "float32" : "float64";
}

// Checks three color channels for n points; whether any uint16 channel holds a value above 255 (16-bit
// data, scaled to 8 bits).
bool checkColors(const py::array (&channels)[3], uint64_t n) {
  const char* names[3] = {"red", "green", "blue"};
  bool wide = false;
  for (int c = 0; c < 3; ++c) {
    checkVector(channels[c], names[c], n, isUint8or16, "uint8 or uint16");
    if (isUint16(channels[c].dtype()))
      for (uint64_t i = 0; i < n && !wide; ++i)
        wide = at<uint16_t>(channels[c], i) > 255;
  }
  return wide;
}

// The packed color of point i from channels read without the interpreter.
inline uint32_t channelColor(const char* const (&data)[3], const py::ssize_t (&stride)[3],
                             const bool (&byte)[3], bool wide, uint64_t i) {
  uint32_t v[3];
  for (int c = 0; c < 3; ++c) {
    const char* p = data[c] + py::ssize_t(i) * stride[c];
    const uint32_t raw = byte[c] ? uint32_t(*reinterpret_cast<const uint8_t*>(p))
                                 : uint32_t(*reinterpret_cast<const uint16_t*>(p));
    v[c] = wide ? raw >> 8 : raw;
  }
  return packRgba(v[0], v[1], v[2]);
}

} // namespace

ArrayPoints::ArrayPoints(const py::array& xyz) : xyz_(xyz) {
  f32_ = std::string(checkXyz(xyz)) == "float32";
  n_ = uint64_t(xyz.shape(0));
  data_ = xyz.data();
  Bounds raw;
  {
    py::gil_scoped_release release; // the array stays referenced by this object
    raw = f32_ ? rawBounds(static_cast<const float*>(data_), n_)
               : rawBounds(static_cast<const double*>(data_), n_);
  }
  shape_.source = "array";
  // The readers' rule (io/io_util.h): offset = the minimum, scale = the power of ten that spans the extent.
  const io::detail::Quantization q = io::detail::chooseQuantization("xyz", raw);
  shape_.scale = q.scale;
  shape_.offset = q.offset;
  if (n_ > 0) {
    // Quantization is monotonic: the quantized bounds are those of the raw bounds' corners.
    int32_t qmin[3], qmax[3];
    for (int a = 0; a < 3; ++a) {
      qmin[a] = io::detail::quantize(raw.min[a], q.scale[a], q.offset[a]);
      qmax[a] = io::detail::quantize(raw.max[a], q.scale[a], q.offset[a]);
    }
    shape_.bounds = io::detail::boundsFromQuantized(qmin, qmax, q.scale, q.offset);
  }
}

void ArrayPoints::setColors(const py::object& red, const py::object& green, const py::object& blue) {
  if (red.is_none() && green.is_none() && blue.is_none()) return;
  if (red.is_none() || green.is_none() || blue.is_none())
    throw py::value_error("colors need all three channels: red, green and blue");
  const py::array channels[3] = {red.cast<py::array>(), green.cast<py::array>(), blue.cast<py::array>()};
  wide_ = checkColors(channels, n_);
  for (int c = 0; c < 3; ++c) {
    channels_[c] = channels[c];
    channelData_[c] = static_cast<const char*>(channels[c].data());
    channelStride_[c] = n_ ? channels[c].strides(0) : 0;
    channelByte_[c] = isUint8(channels[c].dtype());
  }
}

uint32_t ArrayPoints::color(uint64_t i) const {
  return channelColor(channelData_, channelStride_, channelByte_, wide_, i);
}

bool ArrayPoints::colorsShowAtOnce() const {
  if (!hasColor()) return false;
  for (uint64_t i = 0; i < std::min<uint64_t>(n_, 4096); ++i)
    if (color(i) & 0x00FFFFFFu) return true;
  return false;
}

void ArrayPoints::fill(uint64_t first, uint64_t count, PointCloud& out) const {
  out.positions.resize(3 * count);
  if (f32_)
    quantizeRows(static_cast<const float*>(data_) + 3 * first, count, shape_.scale, shape_.offset,
                 out.positions.data());
  else
    quantizeRows(static_cast<const double*>(data_) + 3 * first, count, shape_.scale, shape_.offset,
                 out.positions.data());
  if (hasColor()) {
    out.colors.resize(count);
    uint32_t* dst = out.colors.data();
    if (channelByte_[0] && channelByte_[1] && channelByte_[2]) {
      // 8-bit channels (the usual (N, 3) uint8 array): plain loads, no width to test per point.
      const auto* r = reinterpret_cast<const uint8_t*>(channelData_[0]) + first * channelStride_[0];
      const auto* g = reinterpret_cast<const uint8_t*>(channelData_[1]) + first * channelStride_[1];
      const auto* b = reinterpret_cast<const uint8_t*>(channelData_[2]) + first * channelStride_[2];
      const py::ssize_t sr = channelStride_[0], sg = channelStride_[1], sb = channelStride_[2];
      for (uint64_t i = 0; i < count; ++i)
        dst[i] = packRgba(r[i * sr], g[i * sg], b[i * sb]);
    } else {
      for (uint64_t i = 0; i < count; ++i)
        dst[i] = color(first + i);
    }
  }
}

std::vector<glm::dvec3> ArrayPoints::framingSample(size_t maxPoints) const {
  // The stride of render/camera.h's framingSample(), over the points' quantized positions.
  std::vector<glm::dvec3> sample;
  if (n_ == 0 || maxPoints == 0) return sample;
  const uint64_t step = (n_ + maxPoints - 1) / maxPoints;
  PointCloud one;
  for (uint64_t i = 0; i < n_; i += step) {
    one.scale = shape_.scale;
    one.offset = shape_.offset;
    fill(i, 1, one);
    sample.push_back(one.world(0));
  }
  return sample;
}

std::shared_ptr<PointCloud> ArrayPoints::makeCloud() const {
  auto cloud = std::make_shared<PointCloud>();
  cloud->source = shape_.source;
  cloud->scale = shape_.scale;
  cloud->offset = shape_.offset;
  cloud->bounds = shape_.bounds;
  py::gil_scoped_release release; // the arrays stay referenced by this object
  cloud->positions.resize(3 * n_);
  if (hasColor()) cloud->colors.resize(n_);
  int32_t* dst = cloud->positions.data();
  uint32_t* colors = cloud->colors.data();
  parallelBlocks(n_, kBlock, [&](uint64_t, uint64_t begin, uint64_t end) {
    if (f32_)
      quantizeRows(static_cast<const float*>(data_) + 3 * begin, end - begin, shape_.scale, shape_.offset,
                   dst + 3 * begin);
    else
      quantizeRows(static_cast<const double*>(data_) + 3 * begin, end - begin, shape_.scale, shape_.offset,
                   dst + 3 * begin);
    if (colors)
      for (uint64_t i = begin; i < end; ++i)
        colors[i] = color(i);
  });
  return cloud;
}

std::shared_ptr<PointCloud> cloudFromQuantized(const py::array& x, const py::array& y, const py::array& z,
                                               const glm::dvec3& scale, const glm::dvec3& offset) {
  const uint64_t n = uint64_t(x.ndim() == 1 ? x.shape(0) : 0);
  checkVector(x, "X", n, isInt32, "int32");
  checkVector(y, "Y", n, isInt32, "int32");
  checkVector(z, "Z", n, isInt32, "int32");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(scale[a]) || scale[a] == 0 || !std::isfinite(offset[a]))
      throw py::value_error("scales must be finite and non-zero, offsets finite");
  auto cloud = std::make_shared<PointCloud>();
  cloud->source = "array";
  cloud->scale = scale;
  cloud->offset = offset;
  cloud->positions.resize(3 * n);
  {
    py::gil_scoped_release release;
    for (uint64_t i = 0; i < n; ++i) {
      cloud->positions[3 * i] = at<int32_t>(x, i);
      cloud->positions[3 * i + 1] = at<int32_t>(y, i);
      cloud->positions[3 * i + 2] = at<int32_t>(z, i);
    }
    computeBounds(*cloud);
  }
  return cloud;
}

void setColors(PointCloud& cloud, const py::object& red, const py::object& green, const py::object& blue) {
  if (red.is_none() && green.is_none() && blue.is_none()) return;
  if (red.is_none() || green.is_none() || blue.is_none())
    throw py::value_error("colors need all three channels: red, green and blue");
  const py::array channels[3] = {red.cast<py::array>(), green.cast<py::array>(), blue.cast<py::array>()};
  const uint64_t n = cloud.size();
  const bool wide = checkColors(channels, n);
  cloud.colors.resize(n);
  // Read without the interpreter: each channel's bytes, stride and width taken first.
  const char* data[3];
  py::ssize_t stride[3];
  bool byte[3];
  for (int c = 0; c < 3; ++c) {
    data[c] = static_cast<const char*>(channels[c].data());
    stride[c] = n ? channels[c].strides(0) : 0;
    byte[c] = isUint8(channels[c].dtype());
  }
  uint32_t* dst = cloud.colors.data();
  py::gil_scoped_release release; // the arrays stay referenced by the caller
  parallelBlocks(n, kBlock, [&](uint64_t, uint64_t begin, uint64_t end) {
    for (uint64_t i = begin; i < end; ++i)
      dst[i] = channelColor(data, stride, byte, wide, i);
  });
}

void setAttribute(PointCloud& cloud, const std::string& name, const py::object& values) {
  if (values.is_none()) return;
  const py::array a = values.cast<py::array>();
  const uint64_t n = cloud.size();
  if (name == "intensity") {
    checkVector(a, "intensity", n, isUint8or16, "uint8 or uint16");
    cloud.intensity.resize(n);
    for (uint64_t i = 0; i < n; ++i)
      cloud.intensity[i] = isUint8(a.dtype()) ? at<uint8_t>(a, i) : at<uint16_t>(a, i);
  } else if (name == "classification" || name == "return_number") {
    checkVector(a, name.c_str(), n, isUint8, "uint8");
    (name == "classification" ? cloud.classification : cloud.returnNumber) = copyVector<uint8_t>(a);
  } else if (name == "point_source_id") {
    checkVector(a, "point_source_id", n, isUint16, "uint16");
    cloud.pointSourceId = copyVector<uint16_t>(a);
  } else {
    throw py::value_error("unknown attribute " + name);
  }
}

py::array positionView(const PointCloud& cloud, int axis, const py::object& owner) {
  return py::array(py::dtype::of<int32_t>(), {py::ssize_t(cloud.size())}, {py::ssize_t(3 * sizeof(int32_t))},
                   cloud.positions.data() + axis, owner);
}

py::array colorView(const PointCloud& cloud, int channel, const py::object& owner) {
  if (cloud.colors.empty()) return py::array(py::dtype::of<uint8_t>(), {py::ssize_t(0)}, {py::ssize_t(1)});
  return py::array(py::dtype::of<uint8_t>(), {py::ssize_t(cloud.size())}, {py::ssize_t(sizeof(uint32_t))},
                   reinterpret_cast<const uint8_t*>(cloud.colors.data()) + channel, owner);
}

py::object attributeView(const PointCloud& cloud, const std::string& name, const py::object& owner) {
  auto view = [&](const auto& v) -> py::object {
    using T = typename std::decay_t<decltype(v)>::value_type;
    if (v.empty()) return py::none();
    return py::array(py::dtype::of<T>(), {py::ssize_t(v.size())}, {py::ssize_t(sizeof(T))}, v.data(), owner);
  };
  if (name == "intensity") return view(cloud.intensity);
  if (name == "classification") return view(cloud.classification);
  if (name == "return_number") return view(cloud.returnNumber);
  if (name == "point_source_id") return view(cloud.pointSourceId);
  throw py::value_error("unknown attribute " + name);
}

py::array worldCoordinates(const PointCloud& cloud, int axis) {
  py::array_t<double> out(py::ssize_t(cloud.size()));
  double* dst = out.mutable_data();
  const double scale = cloud.scale[axis], offset = cloud.offset[axis];
  for (uint64_t i = 0; i < cloud.size(); ++i)
    dst[i] = cloud.positions[3 * i + axis] * scale + offset;
  return out;
}

} // namespace pointrast::python
