// The Potree 2.0 attributes of a point's attribute tail (cloud/point_attributes.h), named and typed as
// PotreeConverter 2 names them for LAS inputs ("number of returns", "classification flags", "scan angle
// rank" for formats 0-5 and "scan angle" for 6-10, "user data", "gps-time", extra bytes fields under their
// descriptors' names and types), plus the fields PotreeConverter does not keep under the LAS
// specification's names ("scanner channel", "scan direction flag", "edge of flight line", "nir").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cloud/point_attributes.h"
#include "io/las/las_attributes.h"

namespace pointrast::io::potree {

// One attribute: its bytes are the tail's bytes at tailOffset (size of them), or for a bit field
// (bits > 0) the value (tail[tailOffset] >> shift) & ((1 << bits) - 1) in one byte.
struct TailAttribute {
  std::string name, type, description;
  int size = 0, numElements = 1, elementSize = 0;
  int tailOffset = 0;
  int shift = 0, bits = 0;
};

std::vector<TailAttribute> tailAttributes(const PointAttributes& attributes, const AttributeLayout& layout,
                                          const std::vector<detail::ExtraBytesField>& extraBytes);

} // namespace pointrast::io::potree
