// Node sources whose points carry tails (cloud/point_attributes.h) beside their records: pointrast's
// Potree 2.0 octrees of LAS inputs, PotreeConverter's octrees (the LAS attributes they name), COPC files.
// An export asks a NodeSource for this interface (dynamic_cast) and writes the records back in the point
// format they came from (where tailFormat() names one); a pick shows a point's tail (tailValues).
#pragma once

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "cloud/octree.h"
#include "cloud/point_attributes.h"

namespace pointrast::lod {

// One attribute of a point's tail as a picked point shows it: its key ("gps_time", "number_of_returns",
// "scan_angle" in degrees, "user_data", "nir", "classification_flags", "scanner_channel",
// "scan_direction_flag", "edge_of_flight_line"; an extra bytes field by its descriptor's name) and its
// values (one, or two or three for an array field; an extra bytes field with a scale or offset as
// value * scale + offset), integers kept exact.
struct TailValue {
  using Number = std::variant<int64_t, uint64_t, double>;
  std::string name;
  bool extraBytes = false; // an extra bytes field (its name is the file's, not one of the keys above)
  std::vector<Number> values;
};

class NodeTails {
public:
  virtual ~NodeTails() = default;
  // What the tails hold; no attributes (0 bytes) when the points carry none.
  virtual const TailFormat& tailFormat() const = 0;
  // NodeSource::readNode() plus the points' tails (tailFormat().bytes() each) into tails.
  virtual std::vector<PointRecord> readNodeTails(const NodeInfo& node, std::vector<uint8_t>& tails) = 0;
  // The attributes of one point's tail (tailFormat().bytes() bytes), in the order above.
  virtual std::vector<TailValue> tailValues(const uint8_t* tail) const = 0;
};

} // namespace pointrast::lod
