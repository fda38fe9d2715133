// NumPy arrays to and from the host model (cloud/cloud.h). A cloud keeps int32 positions with a scale and
// offset per axis; float coordinates are quantized exactly as the XYZ and PLY readers quantize theirs, so
// an array renders like the same coordinates read from a file by the CLI. Bad arrays raise TypeError (the
// dtype) or ValueError (shape, layout, values), each naming the argument.
#pragma once

#include <memory>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "cloud/cloud.h"
#include "render/scene.h"

namespace pointrast::python {

namespace py = pybind11;

// xyz: float32 or float64 (N, 3), C-contiguous, every value finite.
// Points as the caller's arrays hold them, before any PointCloud is made: an (N, 3) float32 or float64
// C-contiguous xyz, quantized as the readers would (io/io_util.h: offset the minimum, scale the power of
// ten that spans the extent), and optionally three color channels. An upload reads them block by block
// (PointBlocks: no copy of the input on the host); makeCloud() makes the PointCloud for everything else,
// with the same positions and colors. It references the arrays: made and destroyed with the GIL held,
// read without it.
class ArrayPoints : public PointBlocks {
public:
  // Checks the array (dtype, shape, contiguity; every row finite: ValueError naming the first that is
  // not) and takes its bounds on every core.
  explicit ArrayPoints(const py::array& xyz);
  const PointCloud& shape() const override { return shape_; }
  uint64_t size() const override { return n_; }
  void fill(uint64_t first, uint64_t count, PointCloud& out) const override;
  // The three channels as setColors() takes them (uint8 or uint16, one value per point; 16-bit data, a
  // value above 255, is scaled to 8 bits), referenced, not copied.
  void setColors(const py::object& red, const py::object& green, const py::object& blue);
  bool hasColor() const { return !channels_[0].is_none(); }
  // Whether the colors show something in the first 4096 points: displayColorMode()'s quick test, which
  // decides RGB without a scan of the whole input.
  bool colorsShowAtOnce() const;
  // framingSample() of the cloud these points make (render/camera.h), without making it.
  std::vector<glm::dvec3> framingSample(size_t maxPoints = size_t(1) << 16) const;
  // The PointCloud, made on every core.
  std::shared_ptr<PointCloud> makeCloud() const;

private:
  uint32_t color(uint64_t i) const;
  py::array xyz_;
  const void* data_ = nullptr;
  bool f32_ = false;
  uint64_t n_ = 0;
  PointCloud shape_;
  py::object channels_[3] = {py::none(), py::none(), py::none()};
  const char* channelData_[3] = {};
  py::ssize_t channelStride_[3] = {};
  bool channelByte_[3] = {};
  bool wide_ = false;
};

// x, y, z: int32 (N,) of any stride (laspy's X, Y, Z: fields of its point records), world = q * scale +
// offset per axis as LAS stores them.
std::shared_ptr<PointCloud> cloudFromQuantized(const py::array& x, const py::array& y, const py::array& z,
                                               const glm::dvec3& scale, const glm::dvec3& offset);
// Per-point attributes, each None or an (N,) array of any stride: colors as three channels of uint8 or
// uint16 (16-bit data, any value above 255, is shifted right by 8 as the readers do), intensity uint8 or
// uint16, classification and return number uint8, point source id uint16.
void setColors(PointCloud& cloud, const py::object& red, const py::object& green, const py::object& blue);
void setAttribute(PointCloud& cloud, const std::string& name, const py::object& values);

// Views of a cloud's arrays without a copy; `owner` (the Python object holding the cloud) stays alive as
// long as a view does. channel: 0..2 for X, Y, Z (int32) or red, green, blue (uint8).
py::array positionView(const PointCloud& cloud, int axis, const py::object& owner);
py::array colorView(const PointCloud& cloud, int channel, const py::object& owner);
py::object attributeView(const PointCloud& cloud, const std::string& name, const py::object& owner);
// World coordinates of one axis (float64, a new array): q * scale + offset.
py::array worldCoordinates(const PointCloud& cloud, int axis);

} // namespace pointrast::python
