// Node sources whose points carry tails (cloud/point_attributes.h) beside their records: pointrast's
// Potree 2.0 octrees of LAS inputs. An export asks a NodeSource for this interface (dynamic_cast) and
// writes the records back in the point format they came from.
#pragma once

#include <cstdint>
#include <vector>

#include "cloud/octree.h"
#include "cloud/point_attributes.h"

namespace pointrast::lod {

class NodeTails {
public:
  virtual ~NodeTails() = default;
  // What the tails hold; no attributes (0 bytes) when the points carry none.
  virtual const TailFormat& tailFormat() const = 0;
  // NodeSource::readNode() plus the points' tails (tailFormat().bytes() each) into tails.
  virtual std::vector<PointRecord> readNodeTails(const NodeInfo& node, std::vector<uint8_t>& tails) = 0;
};

} // namespace pointrast::lod
