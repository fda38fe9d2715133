// `tls`: a terrestrial laser scan of a small town square from four scanner positions. The scene is
// analytic (tilted ground plane, axis-aligned boxes for buildings, cars and low walls, vertical
// cylinders for trunks and poles, spheroids for crowns) so every ray is intersected exactly.
//
// A scanner turns about its vertical axis in azimuth steps; at each step its mirror sweeps a vertical
// profile from -60 degrees (the tripod hides the rest) to the zenith with the same angular step. Points
// come scanner by scanner, profile by profile, bottom to top: the scan-line order of real TLS data.
// Rays that hit nothing (sky) or the ground beyond the range limit return no point, and density falls
// with distance because the angular step is fixed.
//
// Exact point count: within a profile every shape subtends an interval of elevation angles, so the
// number of returns of a profile is the size of a union of index intervals, found without casting a
// ray. The angular step is chosen so the scene yields T >= N returns (T within ~1% of N), and output
// point i is return floor(i T / N): an even thinning that keeps the scan order and makes each point a
// pure function of i.
#include <algorithm>
#include <array>
#include <limits>
#include <vector>

#include "base/parallel.h"
#include "cloud/scene.h"

namespace pointrast::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kElevationMin = -60.0 * kPi / 180.0;
constexpr double kElevationMax = 90.0 * kPi / 180.0;
constexpr double kMaxRange = 120.0; // m: ground returns end here (the scene's objects are nearer)
constexpr uint64_t kMinAzimuthSteps = 8;
constexpr double kBaseElevation = 150.0;
constexpr double kPlazaRadius = 26.0;

enum class Kind : uint8_t { Ground, Building, Car, Wall, Pole, Trunk, Crown };

struct Box {
  double x0, y0, z0, x1, y1, z1;
  Kind kind;
  Rgb color;
};
struct Cylinder {
  double cx, cy, radius, z0, z1;
  Kind kind;
  Rgb color;
};
struct Spheroid {
  double cx, cy, cz, radius, radiusZ;
  Rgb color;
};
struct Scanner {
  double x, y, z, height, phase;
};

// A shape's cross-section in one profile's vertical half-plane, in (r, z) about the scanner centre:
// a rectangle [r0, r1] x [zlo, zhi] (boxes, cylinders) or an ellipse (crowns).
struct Candidate {
  enum Type : uint8_t { Rect, Ellipse } type;
  Kind kind;
  uint8_t face; // rect from a box: 0 entered through an x face, 1 through a y face
  uint32_t shape;
  int32_t k0, k1;          // elevation steps that hit it
  double r0, r1, zlo, zhi; // Rect
  double rc, zc, a, b;     // Ellipse: centre and half-axes
};

struct Profile {
  double ux = 0, uy = 0;   // azimuth direction
  double slope = 0;        // ground rise per metre along it
  int32_t groundLast = -1; // steps 0..groundLast hit the ground within range
  std::vector<Candidate> candidates;
  std::vector<std::pair<int32_t, int32_t>> ranges; // merged, ascending
  uint64_t hits = 0;
};

class Random {
public:
  explicit Random(uint64_t seed) : state_(seed) {}
  double next() { return unit16(splitmixMix(state_ += kSplitmixGamma), 0); }
  double range(double lo, double hi) { return lo + (hi - lo) * next(); }

private:
  uint64_t state_;
};

class TlsScene final : public SceneGenerator {
public:
  TlsScene(uint64_t points, uint64_t seed);
  void generate(uint64_t first, uint64_t count, int32_t* positions, uint32_t* colors,
                uint8_t* classes) const override;

private:
  double groundZ(double x, double y) const { return kBaseElevation + gradX_ * x + gradY_ * y; }
  void layout(Random& rng);
  bool clear(double x0, double y0, double x1, double y1, double gap) const;
  void buildProfile(uint64_t profile, uint64_t azimuthSteps, Profile& p) const;
  void countReturns(uint64_t azimuthSteps);
  // top: a box entered through its top face (seen from above), not a side.
  Rgb shadeHit(const Candidate* c, bool top, const glm::dvec3& p, const glm::dvec3& dir, double t,
               uint64_t rnd) const;

  uint64_t points_;
  uint64_t seedKey_;
  uint32_t saltNoise_;
  double gradX_ = 0, gradY_ = 0;
  std::vector<Box> boxes_;
  std::vector<Cylinder> cylinders_;
  std::vector<Spheroid> spheroids_;
  std::vector<Scanner> scanners_;
  std::vector<std::array<double, 4>> footprints_; // placed objects, for spacing

  uint64_t azimuthSteps_ = 0; // A: steps per turn; the elevation step is the same angle
  double step_ = 0;
  std::vector<uint64_t> offsets_; // first return of each profile, plus the total
};

TlsScene::TlsScene(uint64_t points, uint64_t seed) : points_(points) {
  seedKey_ = splitmixMix(seed ^ 0x746c73ull); // "tls"
  saltNoise_ = uint32_t(splitmixAt(seedKey_, 1));
  Random rng(splitmixAt(seedKey_, 2));
  layout(rng);
  if (points == 0) return;
  // Returns grow with the square of the steps per turn: estimate, correct a few times, then creep up
  // until there are at least N.
  uint64_t a = 64;
  countReturns(a);
  for (int iteration = 0; iteration < 6; ++iteration) {
    const double t = double(offsets_.back());
    const uint64_t next = std::max<uint64_t>(
        kMinAzimuthSteps,
        uint64_t(std::ceil(double(a) * std::sqrt(double(points) * 1.004 / std::max(t, 1.0)))));
    if (next == a) break;
    a = next;
    countReturns(a);
  }
  while (offsets_.back() < points) {
    a += std::max<uint64_t>(1, a / 256);
    countReturns(a);
  }
}

bool TlsScene::clear(double x0, double y0, double x1, double y1, double gap) const {
  for (const auto& f : footprints_)
    if (x0 < f[2] + gap && x1 > f[0] - gap && y0 < f[3] + gap && y1 > f[1] - gap) return false;
  return true;
}

void TlsScene::layout(Random& rng) {
  gradX_ = rng.range(-0.015, 0.015);
  gradY_ = rng.range(-0.015, 0.015);
  auto place = [&](double x0, double y0, double x1, double y1, double gap) {
    if (!clear(x0, y0, x1, y1, gap)) return false;
    footprints_.push_back({x0, y0, x1, y1});
    return true;
  };
  // Scanner stations first, in the open square, so no object is placed over one.
  for (int s = 0; s < 4; ++s) {
    const double angle = s * kPi / 2 + rng.range(-0.4, 0.4),
                 radius = s == 0 ? rng.range(0, 3) : rng.range(11, 17);
    const double x = radius * std::cos(angle), y = radius * std::sin(angle), height = rng.range(1.4, 1.8);
    scanners_.push_back({x, y, groundZ(x, y) + height, height, rng.range(0, 2 * kPi)});
    footprints_.push_back({x - 0.5, y - 0.5, x + 0.5, y + 0.5});
  }
  static const Rgb kFacades[] = {{222, 206, 178}, {198, 120, 92}, {236, 230, 214}, {176, 168, 152},
                                 {214, 186, 120}, {160, 92, 70},  {190, 200, 206}};
  for (int k = 0; k < 12; ++k) { // a ring of houses around the square
    const double angle = k * 2 * kPi / 12 + rng.range(-0.15, 0.15), radius = rng.range(34, 46);
    const double w = rng.range(9, 22), d = rng.range(8, 16), h = rng.range(7, 22);
    const double cx = radius * std::cos(angle), cy = radius * std::sin(angle);
    const double x0 = cx - w / 2, y0 = cy - d / 2;
    if (!place(x0, y0, x0 + w, y0 + d, 2.5)) continue;
    const double z = groundZ(cx, cy) - 0.5;
    boxes_.push_back({x0, y0, z, x0 + w, y0 + d, z + 0.5 + h, Kind::Building, kFacades[boxes_.size() % 7]});
  }
  for (int k = 0; k < 5; ++k) { // low walls along the square
    const double angle = rng.range(0, 2 * kPi), radius = rng.range(12, 28), length = rng.range(6, 14);
    const bool alongX = rng.next() < 0.5;
    const double cx = radius * std::cos(angle), cy = radius * std::sin(angle);
    const double hx = alongX ? length / 2 : 0.15, hy = alongX ? 0.15 : length / 2;
    if (!place(cx - hx, cy - hy, cx + hx, cy + hy, 1.5)) continue;
    const double z = groundZ(cx, cy) - 0.3;
    boxes_.push_back(
        {cx - hx, cy - hy, z, cx + hx, cy + hy, z + 0.3 + rng.range(0.9, 1.3), Kind::Wall, {172, 166, 156}});
  }
  static const Rgb kCars[] = {{168, 32, 30}, {32, 64, 140},   {190, 192, 196},
                              {30, 30, 34},  {236, 236, 232}, {40, 110, 70}};
  for (int k = 0; k < 10; ++k) { // parked cars
    const double angle = rng.range(0, 2 * kPi), radius = rng.range(8, 29);
    const bool alongX = rng.next() < 0.5;
    const double cx = radius * std::cos(angle), cy = radius * std::sin(angle);
    const double hx = alongX ? 2.25 : 0.9, hy = alongX ? 0.9 : 2.25;
    if (!place(cx - hx, cy - hy, cx + hx, cy + hy, 1.2)) continue;
    const double z = groundZ(cx, cy) - 0.1;
    boxes_.push_back(
        {cx - hx, cy - hy, z + 0.25, cx + hx, cy + hy, z + 1.5, Kind::Car, kCars[boxes_.size() % 6]});
  }
  for (int k = 0; k < 28; ++k) { // trees: trunk and crown
    const double angle = rng.range(0, 2 * kPi), radius = rng.range(6, 32);
    const double r = rng.range(1.8, 3.6), trunk = rng.range(2.0, 3.5), rz = r * rng.range(1.0, 1.4);
    const double cx = radius * std::cos(angle), cy = radius * std::sin(angle);
    if (!place(cx - r, cy - r, cx + r, cy + r, 1.5)) continue;
    const double z = groundZ(cx, cy);
    const double u = rng.next();
    cylinders_.push_back({cx, cy, rng.range(0.14, 0.3), z - 0.3, z + trunk + rz, Kind::Trunk, {92, 70, 50}});
    spheroids_.push_back({cx, cy, z + trunk + rz, r, rz, mix(Rgb{46, 90, 36}, Rgb{100, 134, 56}, u)});
  }
  for (int k = 0; k < 12; ++k) { // lamp posts
    const double angle = rng.range(0, 2 * kPi), radius = rng.range(5, 30);
    const double cx = radius * std::cos(angle), cy = radius * std::sin(angle);
    if (!place(cx - 0.1, cy - 0.1, cx + 0.1, cy + 0.1, 1.0)) continue;
    const double z = groundZ(cx, cy);
    cylinders_.push_back({cx, cy, 0.08, z - 0.3, z + rng.range(4.5, 6.0), Kind::Pole, {70, 72, 76}});
  }
}

// Index range of elevation steps whose angles lie in [lo, hi].
inline std::pair<int32_t, int32_t> stepRange(double lo, double hi, double step, int32_t steps) {
  const double k0 = std::ceil((lo - kElevationMin) / step - 0.5),
               k1 = std::floor((hi - kElevationMin) / step - 0.5);
  return {int32_t(std::max(k0, 0.0)), int32_t(std::min(k1, double(steps - 1)))};
}

void TlsScene::buildProfile(uint64_t profile, uint64_t azimuthSteps, Profile& p) const {
  const Scanner& sc = scanners_[profile / azimuthSteps];
  const uint64_t azimuth = profile % azimuthSteps;
  const double phi = sc.phase + 2 * kPi * (double(azimuth) + 0.5) / double(azimuthSteps);
  const double step = 2 * kPi / double(azimuthSteps);
  const int32_t steps = int32_t((kElevationMax - kElevationMin) / step);
  p.ux = std::cos(phi);
  p.uy = std::sin(phi);
  p.slope = gradX_ * p.ux + gradY_ * p.uy;
  p.candidates.clear();
  p.ranges.clear();
  p.hits = 0;
  // Ground: a ray at elevation e meets the line z = slope r - height at distance
  // height / (slope cos e - sin e), within kMaxRange iff e <= atan(slope) - asin(height / (R sqrt(1+s^2))).
  const double groundMax =
      std::atan(p.slope) -
      std::asin(std::min(1.0, sc.height / (kMaxRange * std::sqrt(1 + p.slope * p.slope))));
  p.groundLast = stepRange(kElevationMin, groundMax, step, steps).second;
  if (p.groundLast >= 0) p.ranges.push_back({0, p.groundLast});

  auto addRect = [&](Kind kind, uint32_t shape, uint8_t face, double r0, double r1, double z0, double z1) {
    const double zlo = z0 - sc.z, zhi = z1 - sc.z;
    const double e[4] = {std::atan2(zlo, r0), std::atan2(zhi, r0), std::atan2(zlo, r1), std::atan2(zhi, r1)};
    auto [k0, k1] =
        stepRange(std::min({e[0], e[1], e[2], e[3]}), std::max({e[0], e[1], e[2], e[3]}), step, steps);
    if (k0 > k1) return;
    Candidate c{};
    c.type = Candidate::Rect;
    c.kind = kind;
    c.face = face;
    c.shape = shape;
    c.k0 = k0;
    c.k1 = k1;
    c.r0 = r0;
    c.r1 = r1;
    c.zlo = zlo;
    c.zhi = zhi;
    p.candidates.push_back(c);
    p.ranges.push_back({k0, k1});
  };
  for (uint32_t i = 0; i < boxes_.size(); ++i) {
    const Box& b = boxes_[i];
    // Slab clipping of the horizontal ray.
    double lo = 0, hi = std::numeric_limits<double>::infinity();
    uint8_t face = 0;
    bool miss = false;
    const double o[2] = {sc.x, sc.y}, u[2] = {p.ux, p.uy}, bmin[2] = {b.x0, b.y0}, bmax[2] = {b.x1, b.y1};
    for (int axis = 0; axis < 2 && !miss; ++axis) {
      if (std::abs(u[axis]) < 1e-12) {
        miss = o[axis] < bmin[axis] || o[axis] > bmax[axis];
        continue;
      }
      double t0 = (bmin[axis] - o[axis]) / u[axis], t1 = (bmax[axis] - o[axis]) / u[axis];
      if (t0 > t1) std::swap(t0, t1);
      if (t0 > lo) lo = t0, face = uint8_t(axis);
      hi = std::min(hi, t1);
      miss = lo >= hi;
    }
    if (miss || lo <= 0) continue; // stations keep clear of every footprint, so lo <= 0 means behind
    addRect(b.kind, i, face, lo, hi, b.z0, b.z1);
  }
  for (uint32_t i = 0; i < cylinders_.size(); ++i) {
    const Cylinder& c = cylinders_[i];
    const double dx = c.cx - sc.x, dy = c.cy - sc.y;
    const double rc = dx * p.ux + dy * p.uy, d = dx * p.uy - dy * p.ux;
    if (std::abs(d) >= c.radius) continue;
    const double w = std::sqrt(c.radius * c.radius - d * d);
    if (rc - w <= 0) continue;
    addRect(c.kind, i, 0, rc - w, rc + w, c.z0, c.z1);
  }
  for (uint32_t i = 0; i < spheroids_.size(); ++i) {
    const Spheroid& s = spheroids_[i];
    const double dx = s.cx - sc.x, dy = s.cy - sc.y;
    const double rc = dx * p.ux + dy * p.uy, d = dx * p.uy - dy * p.ux;
    if (std::abs(d) >= s.radius) continue;
    const double a = std::sqrt(s.radius * s.radius - d * d), b = s.radiusZ * a / s.radius, zc = s.cz - sc.z;
    if (rc - a <= 0) continue;
    // Scaling z by a/b turns the ellipse into a circle of radius a; its tangent angles map back through
    // tan(e) = tan(e') b / a, which keeps their order.
    const double zs = zc * a / b, dist = std::sqrt(rc * rc + zs * zs);
    const double centre = std::atan2(zs, rc), half = std::asin(std::min(1.0, a / dist));
    const double lo = std::atan(std::tan(centre - half) * b / a),
                 hi = std::atan(std::tan(centre + half) * b / a);
    auto [k0, k1] = stepRange(lo, hi, step, steps);
    if (k0 > k1) continue;
    Candidate c{};
    c.type = Candidate::Ellipse;
    c.kind = Kind::Crown;
    c.shape = i;
    c.k0 = k0;
    c.k1 = k1;
    c.rc = rc;
    c.zc = zc;
    c.a = a;
    c.b = b;
    p.candidates.push_back(c);
    p.ranges.push_back({k0, k1});
  }
  std::sort(p.ranges.begin(), p.ranges.end());
  size_t out = 0;
  for (size_t k = 0; k < p.ranges.size(); ++k) {
    if (out > 0 && p.ranges[k].first <= p.ranges[out - 1].second + 1)
      p.ranges[out - 1].second = std::max(p.ranges[out - 1].second, p.ranges[k].second);
    else
      p.ranges[out++] = p.ranges[k];
  }
  p.ranges.resize(out);
  for (const auto& r : p.ranges)
    p.hits += uint64_t(r.second - r.first + 1);
}

void TlsScene::countReturns(uint64_t azimuthSteps) {
  azimuthSteps_ = azimuthSteps;
  step_ = 2 * kPi / double(azimuthSteps);
  const uint64_t profiles = scanners_.size() * azimuthSteps;
  offsets_.assign(profiles + 1, 0);
  parallelBlocks(profiles, 256, [&](uint64_t, uint64_t begin, uint64_t end) {
    Profile p;
    for (uint64_t k = begin; k < end; ++k) {
      buildProfile(k, azimuthSteps, p);
      offsets_[k + 1] = p.hits;
    }
  });
  for (uint64_t k = 0; k < profiles; ++k)
    offsets_[k + 1] += offsets_[k];
}

Rgb TlsScene::shadeHit(const Candidate* c, bool top, const glm::dvec3& p, const glm::dvec3& dir, double t,
                       uint64_t rnd) const {
  Rgb color;
  glm::dvec3 n(0, 0, 1);
  const Kind kind = c ? c->kind : Kind::Ground;
  auto frac = [](double v) { return v - std::floor(v); };
  switch (kind) {
  case Kind::Ground: {
    const NoiseSample patch = valueNoise(p.x * 0.25, p.y * 0.25, saltNoise_);
    if (std::hypot(p.x, p.y) < kPlazaRadius + 3 * patch.v) {
      // Paving stones of 0.6 m with darker joints, each stone a little different.
      const int32_t ix = int32_t(std::floor(p.x / 0.6)), iy = int32_t(std::floor(p.y / 0.6));
      const bool joint = frac(p.x / 0.6) < 0.05 || frac(p.y / 0.6) < 0.05;
      color = Rgb{170, 162, 150} * ((joint ? 0.7 : 1.0) * (0.9 + 0.15 * unit(hash2(ix, iy, saltNoise_))));
    } else {
      color = mix(Rgb{92, 132, 58}, Rgb{128, 112, 80}, std::clamp(0.5 + patch.v, 0.0, 1.0));
    }
    break;
  }
  case Kind::Building: {
    const Box& b = boxes_[c->shape];
    if (top) {
      color = Rgb{96, 96, 100};
      break;
    }
    n = c->face == 0 ? glm::dvec3(-glm::sign(dir.x), 0, 0) : glm::dvec3(0, -glm::sign(dir.y), 0);
    // Windows: 2.8 m bays, 3.2 m storeys, none on the ground-floor plinth.
    const double along = c->face == 0 ? p.y - b.y0 : p.x - b.x0, up = p.z - b.z0;
    const double fa = frac(along / 2.8), fu = frac(up / 3.2);
    const bool window = up > 1.5 && up < b.z1 - b.z0 - 1.0 && fa > 0.28 && fa < 0.72 && fu > 0.3 && fu < 0.78;
    color = window ? Rgb{54, 64, 80} : b.color;
    break;
  }
  case Kind::Car: {
    const Box& b = boxes_[c->shape];
    color = p.z > b.z0 + 0.6 * (b.z1 - b.z0) ? Rgb{40, 46, 56} : b.color; // windows above the belt line
    n = top            ? glm::dvec3(0, 0, 1)
        : c->face == 0 ? glm::dvec3(-glm::sign(dir.x), 0, 0)
                       : glm::dvec3(0, -glm::sign(dir.y), 0);
    break;
  }
  case Kind::Wall:
    color = boxes_[c->shape].color;
    n = top            ? glm::dvec3(0, 0, 1)
        : c->face == 0 ? glm::dvec3(-glm::sign(dir.x), 0, 0)
                       : glm::dvec3(0, -glm::sign(dir.y), 0);
    break;
  case Kind::Pole:
  case Kind::Trunk: {
    const Cylinder& cy = cylinders_[c->shape];
    color = cy.color;
    n = glm::normalize(glm::dvec3(p.x - cy.cx, p.y - cy.cy, 0));
    break;
  }
  case Kind::Crown: {
    const Spheroid& s = spheroids_[c->shape];
    n = glm::normalize(glm::dvec3((p.x - s.cx) / (s.radius * s.radius), (p.y - s.cy) / (s.radius * s.radius),
                                  (p.z - s.cz) / (s.radiusZ * s.radiusZ)));
    color = s.color * (0.75 + 0.3 * (p.z - s.cz + s.radiusZ) / (2 * s.radiusZ));
    break;
  }
  }
  // Returns weaken with incidence angle and range, as TLS intensity-tinted colors do.
  const double incidence = std::abs(glm::dot(n, dir));
  const double factor =
      (0.6 + 0.4 * incidence) * (1.0 - 0.25 * std::min(1.0, t / kMaxRange)) * (0.92 + 0.16 * unit16(rnd, 0));
  return color * factor;
}

void TlsScene::generate(uint64_t first, uint64_t count, int32_t* positions, uint32_t* colors,
                        uint8_t* classes) const {
  // A terrestrial scan is not classified here: every point is ASPRS 1, unclassified.
  if (classes) std::fill(classes, classes + count, uint8_t(1));
  const uint64_t total = offsets_.back();
  Profile p;
  uint64_t current = ~0ull;
  for (uint64_t n = 0; n < count; ++n) {
    const uint64_t i = first + n;
    const uint64_t j = uint64_t((unsigned __int128)i * total / points_); // total >= points: j is increasing
    if (current == ~0ull || j < offsets_[current] || j >= offsets_[current + 1]) {
      current = uint64_t(std::upper_bound(offsets_.begin(), offsets_.end(), j) - offsets_.begin()) - 1;
      buildProfile(current, azimuthSteps_, p);
    }
    // The (j - offset)-th hit step of this profile.
    uint64_t h = j - offsets_[current];
    int32_t k = 0;
    for (const auto& r : p.ranges) {
      const uint64_t len = uint64_t(r.second - r.first + 1);
      if (h < len) {
        k = r.first + int32_t(h);
        break;
      }
      h -= len;
    }
    const double e = kElevationMin + (k + 0.5) * step_, ce = std::cos(e), se = std::sin(e);
    double best = std::numeric_limits<double>::infinity();
    const Candidate* hit = nullptr;
    bool top = false;
    if (k <= p.groundLast) best = scanners_[current / azimuthSteps_].height / (p.slope * ce - se);
    for (const Candidate& c : p.candidates) {
      if (k < c.k0 || k > c.k1) continue;
      double t;
      bool viaTop = false;
      if (c.type == Candidate::Rect) {
        const double zEnter = se > 0   ? c.zlo / se
                              : se < 0 ? c.zhi / se
                                       : -std::numeric_limits<double>::infinity();
        t = std::max(c.r0 / ce, zEnter);
        viaTop = zEnter > c.r0 / ce;
      } else {
        // In the space scaled by a/b in z the crown is a circle; distances along the ray are unchanged.
        const double dz = se * c.a / c.b, zc = c.zc * c.a / c.b;
        const double dd = ce * ce + dz * dz, dc = ce * c.rc + dz * zc;
        const double disc = dc * dc - dd * (c.rc * c.rc + zc * zc - c.a * c.a);
        t = (dc - std::sqrt(std::max(0.0, disc))) / dd; // grazing rays round onto the silhouette
      }
      if (t < best) {
        best = t;
        hit = &c;
        top = viaTop;
      }
    }
    const Scanner& sc = scanners_[current / azimuthSteps_];
    const glm::dvec3 dir(p.ux * ce, p.uy * ce, se);
    const uint64_t rnd = splitmixAt(seedKey_, i);
    const double t = best * (1.0 + (unit16(rnd, 16) - 0.5) * 4e-4); // ~2 mm ranging noise at 10 m
    const glm::dvec3 point = glm::dvec3(sc.x, sc.y, sc.z) + t * dir;
    positions[3 * n + 0] = quantize(point.x);
    positions[3 * n + 1] = quantize(point.y);
    positions[3 * n + 2] = quantize(point.z);
    colors[n] = toRgba(shadeHit(hit, top, point, dir, best, rnd));
  }
}

} // namespace

std::unique_ptr<SceneGenerator> makeTlsScene(uint64_t points, uint64_t seed) {
  return std::make_unique<TlsScene>(points, seed);
}

} // namespace pointrast::detail
