// The attributes of a point's tail (cloud/point_attributes.h) as a picked point shows them
// (lod::TailValue): the LAS fields under the keys of render --pick --json, the extra bytes fields under
// their descriptors' names, typed and scaled as the descriptors say.
#pragma once

#include <cstdint>
#include <vector>

#include "cloud/lod_tails.h"
#include "io/las/las_attributes.h"

namespace pointrast::io::detail {

class TailValues {
public:
  // Parses the tail's extra bytes descriptors once; descriptors that do not parse leave the extra bytes
  // one undocumented field of bytes ("extra bytes").
  explicit TailValues(const TailFormat& tail);
  // One point's tail, tail.bytes() bytes.
  std::vector<lod::TailValue> operator()(const uint8_t* tail) const;

private:
  TailFormat tail_;
  std::vector<ExtraBytesField> extra_;
};

} // namespace pointrast::io::detail
