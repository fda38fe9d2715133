// The inputs of an octree build as one stream of records in one frame (private to src/io). Several files
// merge into one octree: their records are brought to a common scale and offset, and their colors to one
// bit depth.
//   - Files that share scale and offset (with positive scales) keep their integers exactly.
//   - Otherwise the common scale is the finest of the inputs' scales per axis and the offset the first
//     file's (moved when the merged extent would not fit in 32 bits, and the scale doubled while it still
//     does not, with a warning); a point is converted by rounding q * s / s' + (o - o') / s' to the nearest
//     integer, which is exact when an input's scale is a multiple of the common one (0.01 onto 0.001) and
//     moves points by at most half a common quantum otherwise.
//   - When some inputs have 16-bit colors and others 8-bit ones, the 8-bit values are widened (v * 257),
//     as a 16-bit file of the same colors would hold them.
//   - The attributes beyond PointRecord's travel as tails (cloud/point_attributes.h) holding what any
//     input has; inputs whose attributes cannot share one tail (different extra bytes, scan angles in
//     different units) are refused with one line. The LAS point format and extra bytes descriptors are
//     the first LAS input's. Fields that are zero in every point are left out once the points were
//     read (zero is what an export writes for a field the tail lacks), and the number of returns where
//     it equals the return number in every point (what an export then writes): a file whose GPS
//     times, scan angles... are all zero pays nothing for them. The extra bytes are always kept.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "cloud/detail.h"
#include "io/point_source.h"

namespace pointrast::io::detail {

class BuildInputs {
public:
  explicit BuildInputs(const std::vector<std::filesystem::path>& paths);

  struct Task {
    size_t input;
    size_t piece;
    uint64_t points;
  };
  // Every piece of every input, inputs in the order given.
  const std::vector<Task>& tasks() const { return tasks_; }
  uint64_t points() const { return points_; }
  uint64_t fileBytes() const { return fileBytes_; }
  const glm::dvec3& scale() const { return scale_; }
  const glm::dvec3& offset() const { return offset_; }
  RecordFields fields() const;
  // The inputs' common tail (no attributes: 0 bytes).
  const TailFormat& tail() const { return tail_; }
  // Adds to mask (tail().bytes() bytes) the bits of the tails of n records read with tail(); sets
  // returnsDiffer where a number of returns differs from its record's return number.
  void orTails(const PointRecord* records, const uint8_t* tails, size_t n, uint8_t* mask,
               bool& returnsDiffer) const;
  // Leaves out of tail() the fields whose bytes are zero in mask (the OR of every point's tail), and
  // the number of returns unless returnsDiffer; returns the tail they were read in before, for repack().
  TailFormat pruneTail(const std::vector<uint8_t>& mask, bool returnsDiffer);
  // Tails of `from` into tails of `to` (whose fields are a subset), n of them.
  static void repack(const TailFormat& from, const TailFormat& to, const uint8_t* src, size_t n,
                     uint8_t* dst);
  std::string names() const; // "a.las, b.las"
  size_t count() const { return inputs_.size(); }

  // Records of one piece in the common frame; colors widened once decideColors() has run.
  void read(const Task& task, std::vector<PointRecord>& out) const;
  // The same with each record's tail (tail().bytes() bytes a record) into tails.
  void read(const Task& task, std::vector<PointRecord>& out, std::vector<uint8_t>& tails) const;
  // Facts of a first pass over the records (as read() gave them) of one task.
  struct Scan {
    pointrast::detail::QuantBox box;
    uint16_t colorMax = 0;
  };
  static Scan scan(const std::vector<PointRecord>& records);
  // Decides the color depth from each input's largest color value (the first pass's scans, per task).
  // Returns whether records read before must be widened: widen() then does it.
  bool decideColors(const std::vector<Scan>& scans);
  void widen(const Task& task, std::vector<PointRecord>& records) const;

private:
  struct Input {
    std::unique_ptr<PointSource> source;
    bool identity = true;
    double mul[3] = {1, 1, 1}, add[3] = {0, 0, 0}; // q' = round(q * mul + add)
    uint16_t colorMax = 0;
    bool widenColors = false;
  };
  void chooseFrame();
  void chooseTail();
  void convert(const Input& in, std::vector<PointRecord>& out) const;
  std::vector<Input> inputs_;
  std::vector<Task> tasks_;
  glm::dvec3 scale_{0.001}, offset_{0.0};
  uint64_t points_ = 0;
  uint64_t fileBytes_ = 0;
  bool colorsDecided_ = false;
  TailFormat tail_;
};

} // namespace pointrast::io::detail
