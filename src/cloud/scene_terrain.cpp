// `terrain`: an airborne LiDAR survey over procedural land. Ground from value-noise fBm; land use
// (fields, forest, villages, town, parks) per coarse cell; buildings with flat or gabled roofs and trees
// with ellipsoid or cone crowns per fine cell; straight roads on building-cell borders. Everything is
// a hash of grid coordinates, so any point can be computed alone.
//
// Acquisition follows a survey flown in parallel strips (30% side overlap) with an oscillating mirror:
// point index -> scan line -> (strip, line in strip, sample in line); lines alternate direction (zig-zag)
// and strips alternate heading. Each pulse is a ray from the aircraft, slanted by the scan angle (up to
// 20 degrees), that returns the first surface it meets, so walls facing the aircraft get a few points
// and roofs many, and some pulses pass through tree crowns to the ground, as in real surveys.
#include <array>
#include <limits>

#include "cloud/scene.h"

namespace pointrast::detail {
namespace {

constexpr double kDensity = 20.0;          // pulses per m^2 of a strip, a typical survey density
constexpr double kMinSide = 40.0;          // tiny clouds still show a patch of land
constexpr double kMaxSide = 10000.0;       // past ~2 G points density rises instead of area
constexpr double kMaxStripSpacing = 400.0; // m between flight lines
constexpr double kOverlap = 0.3;           // side overlap of neighbouring strips
constexpr double kTanMaxScan = 0.36397;    // tan(20 deg): half the field of view
constexpr double kBaseElevation = 180.0;   // m above the datum
constexpr double kBuildingCell = 30.0;
constexpr double kBuildingMargin = 4.0; // footprint to cell border; > kRoadHalfWidth
constexpr double kRoadHalfWidth = 3.0;
constexpr double kTreeCell = 7.0;
constexpr double kCrownReach[2] = {-2.5, 9.5}; // a crown stays within this span of its cell (m)
constexpr double kMaxTreeTop = 30.0;           // above the ground under the pulse, bounds the cells visited
constexpr double kMaxRoofTop = 40.0;
constexpr double kCrownPassThrough = 0.25; // share of pulses that reach the ground through a crown

const glm::dvec3 kSun = glm::normalize(glm::dvec3(-1.0, 1.0, 1.6)); // from the north-west, ~50 deg up

enum class Land : uint8_t { Field, Forest, Village, Town, Park };

struct Building {
  bool present = false;
  uint8_t roof = 0; // 0 flat, 1 ridge along x (slopes face +-y), 2 ridge along y (slopes face +-x)
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0, zBase = 0, zEave = 0, rise = 0;
  Rgb roofColor{}, wallColor{};
};

struct Tree {
  bool present = false;
  bool conifer = false;
  double cx = 0, cy = 0, radius = 0, zBottom = 0, zTop = 0;
  Rgb color{};
};

// Ground footprint of one pulse and its slant: the pulse moves by -t in x per metre of height.
struct Pulse {
  double x, y, t;
};

// The first surface a pulse meets coming down from the aircraft.
struct PulseHit {
  enum Kind { kGround, kRoof, kWall, kCrown };
  double best = 0; // largest height above the ground point at which the pulse enters a surface; 0: ground
  Kind kind = kGround;
  glm::dvec3 normal{0, 0, 1};
  // Copies, not pointers: a later cache lookup may evict the cell that was hit.
  Rgb surface{};
  Tree tree;
};

// Direct-mapped memo of per-cell parameters. Consecutive pulses of a scan line visit the same few cells,
// so a cell's parameters (which include a ground-height evaluation) are computed about once per line.
// It memoizes a pure function, so results never depend on what the cache held before.
template <class T, int kBits> class CellCache {
public:
  template <class F> const T& get(int32_t x, int32_t y, const F& compute) {
    const uint64_t key = uint64_t(uint32_t(x)) << 32 | uint32_t(y);
    Slot& s = slots_[(uint32_t(x) * 0x9E3779B1u + uint32_t(y) * 0x85EBCA77u) >> (32 - kBits)];
    if (!s.valid || s.key != key) {
      s.value = compute(x, y);
      s.key = key;
      s.valid = true;
    }
    return s.value;
  }

private:
  struct Slot {
    uint64_t key = 0;
    bool valid = false;
    T value{};
  };
  std::array<Slot, size_t(1) << kBits> slots_{};
};

// 64 random bits for a cell and a purpose.
inline uint64_t cellRandom(int32_t x, int32_t y, uint64_t salt) {
  return splitmixMix(salt ^ (uint64_t(uint32_t(x)) << 32 | uint32_t(y)));
}

inline double smoothstep(double a, double b, double x) {
  double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// Lambert-like shade, 1 for a level surface, never below 0.55 so shadowed sides keep their color.
inline double shade(const glm::dvec3& n) {
  return 0.55 + 0.45 * std::max(0.0, glm::dot(n, kSun)) / kSun.z;
}

class TerrainScene final : public SceneGenerator {
public:
  TerrainScene(uint64_t points, uint64_t seed);
  void generate(uint64_t first, uint64_t count, int32_t* positions, uint32_t* colors,
                uint8_t* classes) const override;

private:
  struct Line; // per scan line constants

  Land landOfCell(int32_t cx, int32_t cy) const;
  Land landAt(double x, double y) const {
    return landOfCell(floorInt(x * invLandCell_), floorInt(y * invLandCell_));
  }
  // Per-range memo of noise lattice cells: [0..3] the ground octaves, [4] the ground-color patches.
  using NoiseCells = std::array<NoiseCell, 5>;
  double ground(double x, double y, double* gx, double* gy, NoiseCells& cells) const;
  double ground(double x, double y) const {
    NoiseCells cells;
    return ground(x, y, nullptr, nullptr, cells);
  }
  bool roadX(int32_t k) const { return k == centerRoad_[0] || unit(hash1(k, saltRoadX_)) < 0.08; }
  bool roadY(int32_t k) const { return k == centerRoad_[1] || unit(hash1(k, saltRoadY_)) < 0.08; }
  // Distance to the nearest road centre line and the coordinate along it.
  double roadDistance(double x, double y, double* along) const;
  Building building(int32_t bx, int32_t by) const;
  Tree tree(int32_t tx, int32_t ty) const;
  Rgb groundColor(double x, double y, double gx, double gy, uint64_t rnd, NoiseCells& cells) const;
  // The steps of generate(): a scan line's constants, a pulse's aim, then what it meets first.
  void startLine(uint64_t g, Line& line) const;
  Pulse aim(const Line& line, uint64_t k, uint64_t rnd) const;
  void hitBuildings(CellCache<Building, 4>& cache, const Pulse& p, double zg, PulseHit& hit) const;
  void hitCrowns(CellCache<Tree, 6>& cache, const Pulse& p, double zg, PulseHit& hit) const;

  double side_;         // of the surveyed square (m)
  uint64_t strips_;     // K
  uint64_t samples_;    // S pulses per scan line
  uint64_t lines_;      // G scan lines in all
  double stripSpacing_; // m between flight lines
  double stripWidth_;   // swath width on the ground
  double flightHeight_; // above the ground, so the swath edge is at the maximum scan angle
  double landCell_, invLandCell_;
  int32_t centerRoad_[2];
  uint64_t seedKey_;
  uint32_t saltNoise_[5], saltLand_, saltRoadX_, saltRoadY_;
  uint64_t saltBuilding_, saltTree_;
};

TerrainScene::TerrainScene(uint64_t points, uint64_t seed) {
  seedKey_ = splitmixMix(seed ^ 0x7465727261696eull); // "terrain"
  for (int k = 0; k < 5; ++k)
    saltNoise_[k] = uint32_t(splitmixAt(seedKey_, k));
  saltLand_ = uint32_t(splitmixAt(seedKey_, 10));
  saltRoadX_ = uint32_t(splitmixAt(seedKey_, 11));
  saltRoadY_ = uint32_t(splitmixAt(seedKey_, 12));
  saltBuilding_ = splitmixAt(seedKey_, 13);
  saltTree_ = splitmixAt(seedKey_, 14);

  side_ = std::clamp(std::sqrt(double(points) / kDensity), kMinSide, kMaxSide);
  strips_ = std::max<uint64_t>(1, uint64_t(std::ceil(side_ / kMaxStripSpacing)));
  stripSpacing_ = side_ / double(strips_);
  stripWidth_ = stripSpacing_ * (strips_ > 1 ? 1.0 + kOverlap : 1.0);
  flightHeight_ = 0.5 * stripWidth_ / kTanMaxScan;
  // Square pulse spacing d: strips_ swaths of stripWidth_ x side_ hold all points.
  const double d = std::sqrt(double(strips_) * stripWidth_ * side_ / std::max<double>(1.0, double(points)));
  samples_ = std::max<uint64_t>(1, uint64_t(std::llround(stripWidth_ / d)));
  lines_ = std::max<uint64_t>(1, (points + samples_ - 1) / samples_);
  strips_ = std::min(strips_, lines_);
  landCell_ = std::clamp(side_ / 3.0, 60.0, 240.0);
  invLandCell_ = 1.0 / landCell_;
  centerRoad_[0] = centerRoad_[1] = floorInt(0.5 * side_ / kBuildingCell);
}

Land TerrainScene::landOfCell(int32_t cx, int32_t cy) const {
  const int32_t center = floorInt(0.5 * side_ / landCell_);
  if (cx == center && cy == center) return Land::Village; // every scene shows some buildings
  const double r = unit(hash2(cx, cy, saltLand_));
  if (r < 0.34) return Land::Field;
  if (r < 0.56) return Land::Forest;
  if (r < 0.82) return Land::Village;
  if (r < 0.90) return Land::Town;
  return Land::Park;
}

double TerrainScene::ground(double x, double y, double* gx, double* gy, NoiseCells& cells) const {
  // Rolling hills: four octaves, wavelengths 520..14 m, amplitudes 16..0.2 m (slopes up to ~15%).
  constexpr double kFrequency[4] = {1 / 520.0, 1 / 170.0, 1 / 55.0, 1 / 14.0};
  constexpr double kAmp[4] = {16.0, 5.0, 1.2, 0.2};
  double h = kBaseElevation, dx = 0, dy = 0;
  for (int k = 0; k < 4; ++k) {
    NoiseSample n = valueNoise(x * kFrequency[k], y * kFrequency[k], saltNoise_[k], cells[k]);
    h += kAmp[k] * n.v;
    dx += kAmp[k] * kFrequency[k] * n.dx;
    dy += kAmp[k] * kFrequency[k] * n.dy;
  }
  if (gx) *gx = dx;
  if (gy) *gy = dy;
  return h;
}

double TerrainScene::roadDistance(double x, double y, double* along) const {
  double best = std::numeric_limits<double>::infinity();
  const int32_t kx = floorInt(x * (1 / kBuildingCell) + 0.5);
  if (roadX(kx)) {
    best = std::abs(x - kx * kBuildingCell);
    *along = y;
  }
  const int32_t ky = floorInt(y * (1 / kBuildingCell) + 0.5);
  if (roadY(ky)) {
    double d = std::abs(y - ky * kBuildingCell);
    if (d < best) {
      best = d;
      *along = x;
    }
  }
  return best;
}

Building TerrainScene::building(int32_t bx, int32_t by) const {
  Building b;
  const double cellX = bx * kBuildingCell, cellY = by * kBuildingCell;
  const Land land = landAt(cellX + 0.5 * kBuildingCell, cellY + 0.5 * kBuildingCell);
  const uint64_t r = cellRandom(bx, by, saltBuilding_), r2 = splitmixMix(r);
  static constexpr double kChance[] = {0.04, 0.0, 0.5, 0.85, 0.03}; // by Land
  if (unit16(r, 0) >= kChance[int(land)]) return b;
  b.present = true;
  const bool town = land == Land::Town;
  const double w = town ? 12 + 10 * unit16(r, 16) : 7 + 8 * unit16(r, 16);
  const double d = town ? 12 + 10 * unit16(r, 32) : 7 + 6 * unit16(r, 32);
  const double span = kBuildingCell - 2 * kBuildingMargin;
  b.x0 = cellX + kBuildingMargin + (span - w) * unit16(r, 48);
  b.y0 = cellY + kBuildingMargin + (span - d) * unit16(r2, 0);
  b.x1 = b.x0 + w;
  b.y1 = b.y0 + d;
  const double u = unit16(r2, 16);
  const double height = town ? 9 + 16 * u * u : 3 + 4 * u;
  const double g = ground(0.5 * (b.x0 + b.x1), 0.5 * (b.y0 + b.y1));
  b.zBase = g - 2.0; // sunk into the slope so no gap opens under a wall
  b.zEave = g + height;
  if (unit16(r2, 32) < (town ? 0.2 : 0.85)) {
    b.roof = w >= d ? 1 : 2; // ridge along the longer side
    b.rise = (0.4 + 0.4 * unit16(r2, 48)) * 0.5 * std::min(w, d);
  }
  static const Rgb kRoofs[] = {{172, 84, 60}, {140, 62, 48}, {82, 84, 90}, {104, 108, 118}, {118, 82, 62}};
  static const Rgb kFlatRoofs[] = {{150, 148, 140}, {120, 120, 118}, {170, 165, 150}};
  static const Rgb kWalls[] = {
      {226, 214, 192}, {204, 192, 170}, {236, 232, 222}, {182, 160, 138}, {152, 84, 64}};
  const uint32_t h = uint32_t(r2);
  b.roofColor = b.roof ? kRoofs[h % 5] : kFlatRoofs[h % 3];
  b.wallColor = kWalls[(h >> 8) % 5];
  return b;
}

Tree TerrainScene::tree(int32_t tx, int32_t ty) const {
  Tree t;
  const uint64_t r = cellRandom(tx, ty, saltTree_), r2 = splitmixMix(r);
  t.cx = tx * kTreeCell + 1.5 + 4.0 * unit16(r, 16);
  t.cy = ty * kTreeCell + 1.5 + 4.0 * unit16(r, 32);
  const Land land = landAt(t.cx, t.cy);
  static constexpr double kChance[] = {0.015, 0.85, 0.18, 0.06, 0.35}; // by Land
  if (unit16(r, 0) >= kChance[int(land)]) return t;
  double along;
  if (roadDistance(t.cx, t.cy, &along) < kRoadHalfWidth + 1.5) return t;
  const bool forest = land == Land::Forest;
  t.radius = forest ? 2.0 + 2.0 * unit16(r, 48) : 1.8 + 2.2 * unit16(r, 48);
  const Building b = building(floorInt(t.cx / kBuildingCell), floorInt(t.cy / kBuildingCell));
  const double clear = t.radius + 1.0;
  if (b.present && t.cx > b.x0 - clear && t.cx < b.x1 + clear && t.cy > b.y0 - clear && t.cy < b.y1 + clear)
    return t;
  t.present = true;
  t.conifer = unit16(r2, 0) < (forest ? 0.55 : 0.15);
  const double height = forest ? 12 + 13 * unit16(r2, 16) : 5 + 10 * unit16(r2, 16);
  const double g = ground(t.cx, t.cy);
  t.zTop = g + height;
  if (t.conifer) {
    t.zBottom = g + 0.15 * height;
    t.radius = std::min(t.radius, 0.3 * height);
  } else {
    t.zBottom = g + (0.3 + 0.15 * unit16(r2, 32)) * height;
  }
  const double u = unit16(r2, 48), brightness = 0.8 + 0.35 * unit(uint32_t(r2 >> 7));
  if (t.conifer)
    t.color = mix(Rgb{30, 62, 38}, Rgb{52, 88, 50}, u) * brightness;
  else if (!forest && u > 0.94)
    t.color = Rgb{170, 112, 42} * brightness; // an early autumn tree here and there
  else
    t.color = mix(Rgb{48, 92, 38}, Rgb{96, 130, 54}, u) * brightness;
  return t;
}

Rgb TerrainScene::groundColor(double x, double y, double gx, double gy, uint64_t rnd,
                              NoiseCells& cells) const {
  Rgb c;
  double along = 0;
  const double road = roadDistance(x, y, &along);
  if (road < kRoadHalfWidth) {
    c = Rgb{70, 70, 74};
    if (road < 0.12 && std::fmod(std::abs(along), 9.0) < 3.0) c = Rgb{228, 228, 218}; // centre dashes
  } else {
    const int32_t lx = floorInt(x * invLandCell_), ly = floorInt(y * invLandCell_);
    const Land land = landOfCell(lx, ly);
    const NoiseSample patch = valueNoise(x * 0.2, y * 0.2, saltNoise_[4], cells[4]); // 5 m patches
    switch (land) {
    case Land::Field: {
      static const Rgb kCrops[] = {
          {196, 176, 104}, {112, 142, 62}, {128, 98, 72}, {104, 136, 66}, {160, 150, 80}};
      const uint32_t h = hash2(lx, ly, saltLand_ ^ 0x55u);
      const double coord = (h & 1) ? x : y; // rows run along one axis per field
      const double phase = coord / 2.4 - floorInt(coord / 2.4);
      c = kCrops[(h >> 1) % 5] * (0.9 + 0.2 * std::abs(2 * phase - 1)) * (0.95 + 0.05 * patch.v);
      break;
    }
    case Land::Forest:
      c = mix(Rgb{72, 74, 46}, Rgb{96, 84, 60}, 0.5 + 0.5 * patch.v);
      break;
    case Land::Town:
      c = mix(Rgb{150, 148, 142}, Rgb{96, 132, 62}, smoothstep(0.3, 0.6, patch.v));
      break;
    case Land::Village:
    case Land::Park:
      c = mix(Rgb{96, 136, 60}, Rgb{132, 114, 82}, smoothstep(0.2, 0.7, patch.v));
      break;
    }
  }
  const glm::dvec3 n = glm::normalize(glm::dvec3(-gx, -gy, 1.0));
  return c * (shade(n) * (0.94 + 0.12 * unit16(rnd, 40)));
}

struct TerrainScene::Line {
  uint64_t index = ~0ull; // global scan line g
  double xCenter = 0;     // flight line
  double y = 0;           // along-track position before jitter
  double dy = 0;          // line spacing in this strip
  bool flipY = false, flipX = false;
};

// Normal of the face a pulse entered a building by, `m` the slope of a gabled roof.
glm::dvec3 buildingFaceNormal(int face, double m) {
  switch (face) {
  case 0:
    return {-1, 0, 0};
  case 1:
    return {1, 0, 0};
  case 3:
    return glm::normalize(glm::dvec3(0, m, 1));
  case 4:
    return glm::normalize(glm::dvec3(0, -m, 1));
  case 5:
    return glm::normalize(glm::dvec3(m, 0, 1));
  case 6:
    return glm::normalize(glm::dvec3(-m, 0, 1));
  default:
    return {0, 0, 1};
  }
}

// Records where the pulse enters building `b` when that is higher than what it met so far.
void hitBuilding(const Building& b, const Pulse& p, double zg, PulseHit& hit) {
  const double x = p.x, y = p.y, t = p.t;
  if (!b.present || y < b.y0 || y > b.y1) return;
  // Convex cross-section in the pulse's plane (y fixed): constraints coef * lambda <= rhs.
  double hi = std::numeric_limits<double>::infinity(), lo = -hi;
  int face = -1;
  auto constrain = [&](double coef, double rhs, int f) {
    if (coef > 0) {
      if (rhs / coef < hi) hi = rhs / coef, face = f;
    } else if (coef < 0) {
      lo = std::max(lo, rhs / coef);
    } else if (rhs < 0) {
      hi = -std::numeric_limits<double>::infinity();
    }
  };
  constrain(t, x - b.x0, 0);  // x >= x0: west wall
  constrain(-t, b.x1 - x, 1); // x <= x1: east wall
  constrain(-1, zg - b.zBase, -1);
  double m = 0;
  if (b.roof == 0) {
    constrain(1, b.zEave - zg, 2);
  } else if (b.roof == 1) {
    const double yc = 0.5 * (b.y0 + b.y1), half = 0.5 * (b.y1 - b.y0);
    m = b.rise / half;
    constrain(1, b.zEave + b.rise * (1 - std::abs(y - yc) / half) - zg, y >= yc ? 3 : 4);
  } else {
    const double xc = 0.5 * (b.x0 + b.x1);
    m = b.rise / (0.5 * (b.x1 - b.x0));
    constrain(1 - m * t, b.zEave + b.rise - zg - m * (x - xc), 5); // east-facing slope
    constrain(1 + m * t, b.zEave + b.rise - zg + m * (x - xc), 6); // west-facing slope
  }
  if (lo > hi || hi <= hit.best) return;
  hit.best = hi;
  hit.kind = face <= 1 ? PulseHit::kWall : PulseHit::kRoof;
  hit.surface = face <= 1 ? b.wallColor * 0.9 : b.roofColor;
  hit.normal = buildingFaceNormal(face, m);
}

// Height above the ground point at which the pulse enters crown `tr`; false when it misses.
bool crownEntry(const Tree& tr, const Pulse& p, double zg, double* lambda) {
  const double y = p.y, t = p.t;
  if (!tr.present || std::abs(y - tr.cy) > tr.radius) return false;
  const double a = p.x - tr.cx, b = y - tr.cy;
  if (tr.conifer) {
    // Cone, apex at zTop: horizontal distance <= k (zTop - z).
    const double kk = tr.radius / (tr.zTop - tr.zBottom), c = tr.zTop - zg;
    const double qa = t * t - kk * kk, qb = -2 * a * t + 2 * kk * kk * c,
                 qc = a * a + b * b - kk * kk * c * c;
    const double disc = qb * qb - 4 * qa * qc;
    if (disc < 0) return false;
    const double sq = std::sqrt(disc), r1 = (-qb + sq) / (2 * qa), r2 = (-qb - sq) / (2 * qa);
    *lambda = -std::numeric_limits<double>::infinity();
    if (r1 <= c) *lambda = r1;
    if (r2 <= c) *lambda = std::max(*lambda, r2);
    return !(zg + *lambda < tr.zBottom); // not >=: a NaN entry stays a hit
  }
  const double rz = 0.5 * (tr.zTop - tr.zBottom), e = zg - 0.5 * (tr.zTop + tr.zBottom);
  const double ir2 = 1.0 / (tr.radius * tr.radius), irz2 = 1.0 / (rz * rz);
  const double qa = t * t * ir2 + irz2, qb = -2 * a * t * ir2 + 2 * e * irz2;
  const double qc = (a * a + b * b) * ir2 + e * e * irz2 - 1;
  const double disc = qb * qb - 4 * qa * qc;
  if (disc < 0) return false;
  *lambda = (-qb + std::sqrt(disc)) / (2 * qa);
  return true;
}

// Color of a crown return at (px, y, pz): shaded by the crown's normal there, inner and lower parts darker.
Rgb crownColor(const Tree& tr, double px, double y, double pz, uint64_t rnd) {
  const double h = (pz - tr.zBottom) / (tr.zTop - tr.zBottom);
  glm::dvec3 nr(px - tr.cx, y - tr.cy, 0);
  if (tr.conifer) {
    nr = glm::length(nr) > 0 ? glm::normalize(nr) : glm::dvec3(0);
    nr.z = tr.radius / (tr.zTop - tr.zBottom);
  } else {
    const double rz = 0.5 * (tr.zTop - tr.zBottom);
    nr /= tr.radius * tr.radius;
    nr.z = (pz - 0.5 * (tr.zTop + tr.zBottom)) / (rz * rz);
  }
  return tr.color * ((0.7 + 0.35 * std::clamp(h, 0.0, 1.0)) * shade(glm::normalize(nr)) *
                     (0.85 + 0.3 * unit16(rnd, 40)));
}

void TerrainScene::startLine(uint64_t g, Line& line) const {
  // Strip s holds lines [floor(s G / K), floor((s + 1) G / K)): strips differ by at most one line.
  const uint64_t s = ((g + 1) * strips_ - 1) / lines_;
  const uint64_t g0 = s * lines_ / strips_, g1 = (s + 1) * lines_ / strips_;
  const uint64_t l = g - g0;
  line.index = g;
  line.xCenter = (double(s) + 0.5) * stripSpacing_;
  line.dy = side_ / double(g1 - g0);
  line.y = (double(l) + 0.5) * line.dy;
  line.flipY = s & 1; // alternate headings
  line.flipX = l & 1; // zig-zag mirror
}

Pulse TerrainScene::aim(const Line& line, uint64_t k, uint64_t rnd) const {
  // Pulse footprint on the ground, jittered by up to 30% of the spacing so no grid pattern shows.
  double u = ((double(k) + 0.2 + 0.6 * unit16(rnd, 0)) / double(samples_) - 0.5) * stripWidth_;
  if (line.flipX) u = -u;
  double y = line.y + (unit16(rnd, 16) - 0.5) * 0.6 * line.dy;
  if (line.flipY) y = side_ - y;
  return {line.xCenter + u, y, u / flightHeight_};
}

void TerrainScene::hitBuildings(CellCache<Building, 4>& cache, const Pulse& p, double zg,
                                PulseHit& hit) const {
  auto buildingAt = [this](int32_t x, int32_t y) { return building(x, y); };
  const double xa = std::min(p.x, p.x - p.t * kMaxRoofTop), xb = std::max(p.x, p.x - p.t * kMaxRoofTop);
  const int32_t by = floorInt(p.y / kBuildingCell);
  for (int32_t bx = floorInt(xa / kBuildingCell); bx <= floorInt(xb / kBuildingCell); ++bx)
    hitBuilding(cache.get(bx, by, buildingAt), p, zg, hit);
}

void TerrainScene::hitCrowns(CellCache<Tree, 6>& cache, const Pulse& p, double zg, PulseHit& hit) const {
  auto treeAt = [this](int32_t x, int32_t y) { return tree(x, y); };
  const double xa = std::min(p.x, p.x - p.t * kMaxTreeTop), xb = std::max(p.x, p.x - p.t * kMaxTreeTop);
  const int32_t tx0 = -floorInt((kCrownReach[1] - xa) / kTreeCell);
  const int32_t tx1 = floorInt((xb - kCrownReach[0]) / kTreeCell);
  const int32_t ty0 = -floorInt((kCrownReach[1] - p.y) / kTreeCell);
  const int32_t ty1 = floorInt((p.y - kCrownReach[0]) / kTreeCell);
  for (int32_t ty = ty0; ty <= ty1; ++ty) {
    for (int32_t tx = tx0; tx <= tx1; ++tx) {
      const Tree& tr = cache.get(tx, ty, treeAt);
      double lambda;
      if (!crownEntry(tr, p, zg, &lambda) || lambda <= hit.best) continue;
      hit.best = lambda;
      hit.kind = PulseHit::kCrown;
      hit.tree = tr;
    }
  }
}

void TerrainScene::generate(uint64_t first, uint64_t count, int32_t* positions, uint32_t* colors,
                            uint8_t* classes) const {
  CellCache<Building, 4> buildings;
  CellCache<Tree, 6> trees;
  NoiseCells cells;

  uint64_t g = first / samples_, k = first % samples_;
  Line line;
  for (uint64_t n = 0; n < count; ++n, ++k) {
    if (k == samples_) {
      k = 0;
      ++g;
    }
    if (line.index != g) startLine(g, line);
    const uint64_t i = first + n;
    const uint64_t rnd = splitmixAt(seedKey_, i);
    const Pulse p = aim(line, k, rnd);
    const double x = p.x, y = p.y;

    double gx, gy;
    const double zg = ground(x, y, &gx, &gy, cells);

    PulseHit hit;
    hitBuildings(buildings, p, zg, hit);
    if (unit16(rnd, 32) >= kCrownPassThrough) hitCrowns(trees, p, zg, hit);

    const double px = x - p.t * hit.best;
    const double pz = zg + hit.best + (unit16(rnd, 48) - 0.5) * 0.03; // ~1 cm ranging noise
    positions[3 * n + 0] = quantize(px);
    positions[3 * n + 1] = quantize(y);
    positions[3 * n + 2] = quantize(pz);

    Rgb c;
    const double grain = 0.93 + 0.14 * unit16(rnd, 40);
    switch (hit.kind) {
    case PulseHit::kGround:
      c = groundColor(x, y, gx, gy, rnd, cells);
      break;
    case PulseHit::kRoof:
    case PulseHit::kWall:
      c = hit.surface * (shade(hit.normal) * grain);
      break;
    case PulseHit::kCrown:
      c = crownColor(hit.tree, px, y, pz, rnd);
      break;
    }
    colors[n] = toRgba(c);
    // ASPRS: 2 ground, 6 building (roofs and walls), 5 high vegetation.
    if (classes) classes[n] = hit.kind == PulseHit::kGround ? 2 : hit.kind == PulseHit::kCrown ? 5 : 6;
  }
}

} // namespace

std::unique_ptr<SceneGenerator> makeTerrainScene(uint64_t points, uint64_t seed) {
  return std::make_unique<TerrainScene>(points, seed);
}

} // namespace pointrast::detail
