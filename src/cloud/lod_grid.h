// The octree's frame: its cube, the Morton codes that place a point in every node at once, and the grid
// that subsamples a node. Pure arithmetic on PointRecord integers; no files.
//
// Code layout: 21 levels of 3 bits, level 1 in the top triple; each triple is a child index as NodeKey
// numbers them (x << 2 | y << 1 | z), so sorting by code is depth-first order with children in index order:
//
//   bit  62 61 60 | 59 58 57 | ... | 2  1  0
//        x  y  z  | x  y  z  | ... | x  y  z
//        level 1  | level 2  | ... | level 21
//
// The node at level L containing a point is code >> 3 * (21 - L). Bit 63 is free (the indexer marks
// points taken by a node's subsample with it).
#pragma once

#include <cstdint>

#include "cloud/detail.h"
#include "cloud/octree.h"
#include "cloud/point_record.h"

namespace pointrast::lod {

inline constexpr int kCodeLevels = 21;
// The deepest node: its cube is one code cell, so its points cannot be told apart by the code and it is
// a leaf whatever its count (many copies of one point end there instead of splitting forever).
inline constexpr int kMaxLevel = kCodeLevels;
// Root spacing = cube edge / 2^7 = edge / 128, as PotreeConverter (and the 2022 paper's octrees) use.
inline constexpr int kDefaultGridLevels = 7;
// Finest level of the point-count histogram that chunks are planned from (8^7 = 2 M cells, 16 MB).
inline constexpr int kMaxCountLevel = 7;
inline constexpr uint64_t kTakenBit = uint64_t(1) << 63;

struct LodGrid {
  int32_t qmin[3] = {0, 0, 0};  // the cube's lower corner in quantized coordinates (the points' minimum)
  double toCode[3] = {0, 0, 0}; // code cells per quantum: 2^21 / (cube edge in quanta) per axis
  int gridLevels = kDefaultGridLevels; // a node's subsample grid has 2^gridLevels cells per edge
  Bounds cube;                         // world coordinates, all edges equal
  glm::dvec3 scale{1.0}, offset{0.0};  // of the records

  // Level of the grid cells that subsample a node at `level`: a cell of that grid is an octree cell,
  // deeper by gridLevels, down to the code's resolution.
  int sampleLevel(int level) const {
    return level + gridLevels < kCodeLevels ? level + gridLevels : kCodeLevels;
  }
  // Level of the histogram cells chunks are made of; never deeper than a root grid cell, so every grid cell
  // of every node lies within one chunk.
  int countLevel() const { return gridLevels < kMaxCountLevel ? gridLevels : kMaxCountLevel; }
  double spacing() const { return (cube.max.x - cube.min.x) / double(uint64_t(1) << gridLevels); }

  // Position in code units (0 .. 2^21 along each axis of the cube).
  void codeSpace(const PointRecord& r, double u[3]) const {
    u[0] = double(int64_t(r.x) - qmin[0]) * toCode[0];
    u[1] = double(int64_t(r.y) - qmin[1]) * toCode[1];
    u[2] = double(int64_t(r.z) - qmin[2]) * toCode[2];
  }
  // The center of a cell, in doubled quanta (2 q), rounded to an integer: what a subsample measures
  // distances to.
  struct Center {
    int64_t twice[3];
  };
  Center cellCenter(uint64_t cell, int cellLevel) const;
  // How far a point is from a cell's center, as a subsample ranks points: the squared distance in doubled
  // quanta. With equal scales on all axes (isotropic, the usual case) all integer: exact, and cheap;
  // otherwise each axis weighted by its scale, in double.
  bool isotropic = true;
  int64_t edgeQuanta = 0; // the cube's edge in quanta when isotropic
  double centerDistance(const Center& center, const PointRecord& r) const {
    const int64_t d[3] = {2 * int64_t(r.x) - center.twice[0], 2 * int64_t(r.y) - center.twice[1],
                          2 * int64_t(r.z) - center.twice[2]};
    if (isotropic) return double(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const double w[3] = {double(d[0]) * scale.x, double(d[1]) * scale.y, double(d[2]) * scale.z};
    return w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
  }
  // The same for equal scales, in integers (isotropic must hold).
  uint64_t centerDistanceIsotropic(const Center& center, const PointRecord& r) const {
    const int64_t d[3] = {2 * int64_t(r.x) - center.twice[0], 2 * int64_t(r.y) - center.twice[1],
                          2 * int64_t(r.z) - center.twice[2]};
    return uint64_t(d[0] * d[0]) + uint64_t(d[1] * d[1]) + uint64_t(d[2] * d[2]);
  }

  // The 21-bit cell of each axis that a point's code interleaves.
  void codeCells(const PointRecord& r, uint32_t c[3]) const {
    double u[3];
    codeSpace(r, u);
    for (int a = 0; a < 3; ++a)
      c[a] = u[a] < double((1u << kCodeLevels) - 1) ? static_cast<uint32_t>(u[a]) : (1u << kCodeLevels) - 1;
  }
  uint64_t code(const PointRecord& r) const {
    uint32_t c[3];
    codeCells(r, c);
    return spread21(c[0]) << 2 | spread21(c[1]) << 1 | spread21(c[2]);
  }
  // detail::spreadBits3 through the 7-bit table: three loads instead of five shift-or-mask steps.
  static uint64_t spread21(uint32_t v) {
    return uint64_t(detail::kSpread7.value[v & 127]) |
           uint64_t(detail::kSpread7.value[(v >> 7) & 127]) << 21 |
           uint64_t(detail::kSpread7.value[v >> 14]) << 42;
  }
  // code(r) >> 3 * (21 - countLevel()), the point's histogram cell, for less: its 7 or fewer bits per
  // axis interleave through a table.
  uint32_t countCell(const PointRecord& r) const {
    uint32_t c[3];
    codeCells(r, c);
    const int drop = kCodeLevels - countLevel();
    return detail::kSpread7.value[c[0] >> drop] << 2 | detail::kSpread7.value[c[1] >> drop] << 1 |
           detail::kSpread7.value[c[2] >> drop];
  }
};

// The key of the node at `level` whose cube holds a code.
inline NodeKey keyOfCode(uint64_t code, int level) {
  const uint64_t cell = (code & ~kTakenBit) >> 3 * (kCodeLevels - level);
  return {level, int32_t(detail::compactBits3(cell >> 2)), int32_t(detail::compactBits3(cell >> 1)),
          int32_t(detail::compactBits3(cell))};
}
// The Morton index of a node among the cells of its level (the inverse of keyOfCode).
inline uint64_t cellOfKey(const NodeKey& key) {
  return detail::spreadBits3(uint32_t(key.x)) << 2 | detail::spreadBits3(uint32_t(key.y)) << 1 |
         detail::spreadBits3(uint32_t(key.z));
}

// The frame for points whose quantized extremes are box (not empty), with positive scales: the cube's
// corner is the points' minimum and its edge the largest extent plus one quantum, so the largest
// coordinate lies inside, not on the far face. gridLevels: 1 .. 14.
LodGrid makeLodGrid(const detail::QuantBox& box, const glm::dvec3& scale, const glm::dvec3& offset,
                    int gridLevels = kDefaultGridLevels);

// Grid levels that make the root spacing (edge / 2^levels) closest to `spacing` (by ratio), within
// 4 .. 14 (16 to 16384 cells per node edge). spacing <= 0 gives kDefaultGridLevels.
int gridLevelsForSpacing(double edge, double spacing);

} // namespace pointrast::lod
