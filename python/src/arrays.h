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

namespace pointrast::python {

namespace py = pybind11;

// xyz: float32 or float64 (N, 3), C-contiguous, every value finite.
std::shared_ptr<PointCloud> cloudFromXyz(const py::array& xyz);
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
