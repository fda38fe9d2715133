// The four particle scenes. Each is laid out once from (count, seed); particle i then depends only on
// the layout and i (see particle_scenes.h). Lengths are in units of the dense phases' nearest-neighbor
// distance; every scene is centered near the origin.
//
// particles-block (the Riemann data: a shock tube, dense liquid between two vapor regions): 90% of the
//   particles on a simple cubic lattice of spacing 1 filling a 2:1:1 block, with thermal jitter that
//   grows toward the block's faces (the evaporating surface); 10% vapor in the tube on both sides of
//   the block, densest next to it (mean density 0.05), hotter the farther it flew.
// particles-drops (the Drop/Fluid data): 95% liquid at density 0.9 in 48 droplets of skewed sizes and
//   16 filaments joining droplets to their nearest neighbors; 5% sparse vapor filling the box around
//   them.
// particles-laser (Laser ablation): 7/8 of the particles in an fcc crystal slab (nearest neighbors at
//   distance 1) whose top has a molten crater; 1/8 ejected above it in a cone, 4/5 of those in 256
//   liquid clusters of skewed sizes, 1/5 single vapor atoms.
// particles-uniform: uniform random in a cube at density 1.
//
// Colors are particleRamp() over a phase or speed: cold dense phases blue, molten surfaces, fast
// clusters and hot vapor toward red.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "cloud/detail.h"
#include "cloud/particle_scenes.h"

namespace pointrast::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The random numbers of one particle (or of a layout): a splitmix64 stream started at a hashed state,
// so the streams of neighboring indices do not overlap.
class Rng {
public:
  Rng(uint64_t key, uint64_t index) : state_(splitmixAt(key, index)) {}
  uint64_t next() { return splitmixMix(state_ += kSplitmixGamma); }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; } // [0, 1)
  double range(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double jitter() { return uniform() + uniform() - 1.0; } // triangular on (-1, 1): thermal-looking noise
  glm::dvec3 jitter3() { return {jitter(), jitter(), jitter()}; }
  // Uniform in the unit ball: a uniform direction, radius cbrt(u).
  glm::dvec3 inBall() {
    const double z = 2 * uniform() - 1, phi = 2 * kPi * uniform(), r = std::cbrt(uniform());
    const double s = std::sqrt(std::max(0.0, 1 - z * z));
    return r * glm::dvec3(s * std::cos(phi), s * std::sin(phi), z);
  }

private:
  uint64_t state_;
};

// Site of output particle i when n particles thin a lattice of capacity >= n sites: every site is used
// at most once, and the vacancies spread evenly instead of leaving a partial last layer.
inline uint64_t thinnedSite(uint64_t i, uint64_t capacity, uint64_t n) {
  return static_cast<uint64_t>(static_cast<unsigned __int128>(i) * capacity / n);
}

// Splits n particles over objects in proportion to their weights: object j gets [offsets[j], offsets[j+1]).
std::vector<uint64_t> apportion(const std::vector<double>& weights, uint64_t n) {
  const double total = std::accumulate(weights.begin(), weights.end(), 0.0);
  std::vector<uint64_t> offsets(weights.size() + 1, 0);
  double sum = 0;
  for (size_t j = 0; j + 1 < weights.size(); ++j) {
    sum += weights[j];
    offsets[j + 1] = std::min(n, static_cast<uint64_t>(double(n) * (sum / total)));
  }
  offsets.back() = n;
  return offsets;
}

// The object whose range holds particle i (objects that got no particles are skipped).
size_t objectOf(const std::vector<uint64_t>& offsets, uint64_t i) {
  return size_t(std::upper_bound(offsets.begin(), offsets.end(), i) - offsets.begin()) - 1;
}

// What a scene computes per particle: position, ramp value, and radius relative to the global radius.
struct Particle {
  glm::dvec3 p{0};
  double t = 0;
  double size = 1;
};

class SceneBase : public ParticleGenerator {
public:
  SceneBase(uint64_t seed, uint64_t salt, float radius) : key_(splitmixMix(seed ^ salt)), radius_(radius) {}
  void generate(uint64_t first, uint64_t count, float* xyz, uint32_t* colors, float* radius) const final {
    for (uint64_t k = 0; k < count; ++k) {
      const Particle q = particle(first + k);
      xyz[3 * k] = static_cast<float>(q.p.x);
      xyz[3 * k + 1] = static_cast<float>(q.p.y);
      xyz[3 * k + 2] = static_cast<float>(q.p.z);
      colors[k] = rampColor(q.t);
      if (radius) radius[k] = static_cast<float>(radius_ * q.size);
    }
  }

protected:
  virtual Particle particle(uint64_t i) const = 0;
  // The layout's own stream: particle streams start at splitmixAt(key_, i), i < 2^40.
  Rng layoutRng() const { return Rng(key_, ~uint64_t(0)); }
  uint64_t key_;
  double radius_;
};

// ---- particles-block -------------------------------------------------------------------------------

class BlockScene final : public SceneBase {
public:
  BlockScene(uint64_t n, uint64_t seed, float radius) : SceneBase(seed, 0x626c6f636bull, radius) {
    gas_ = n / 10;
    block_ = n - gas_;
    // Lattice 2k x k x k: the smallest k with room for every block particle.
    k_ = std::max<uint64_t>(1, static_cast<uint64_t>(std::cbrt(double(block_) / 2)));
    while (2 * k_ * k_ * k_ < block_)
      ++k_;
    capacity_ = 2 * k_ * k_ * k_;
    half_ = glm::dvec3(double(k_), k_ / 2.0, k_ / 2.0);
    // The tube has the block's cross-section; each vapor region is as long as kGasDensity needs.
    gasLength_ = double(gas_) / (kGasDensity * 2 * (2 * half_.y) * (2 * half_.z));
  }

private:
  static constexpr double kGasDensity = 0.05;

  Particle particle(uint64_t i) const override {
    Rng rng(key_, i);
    Particle q;
    if (i < block_) {
      const uint64_t s = thinnedSite(i, capacity_, block_), nx = 2 * k_;
      const glm::dvec3 site =
          glm::dvec3(double(s % nx) + 0.5, double((s / nx) % k_) + 0.5, double(s / (nx * k_)) + 0.5) - half_;
      // Depth below the nearest face: the outer layers are hotter and less ordered.
      const double depth =
          std::min({half_.x - std::abs(site.x), half_.y - std::abs(site.y), half_.z - std::abs(site.z)});
      const double hot = std::exp(-(depth - 0.5) / 2.0);
      q.p = site + (0.06 + 0.22 * hot) * rng.jitter3();
      q.t = 0.12 + 0.33 * hot + 0.04 * rng.jitter();
      q.size = 1 + 0.04 * rng.jitter();
      return q;
    }
    // Vapor on either side of the block, its density falling with the distance d from the block's face.
    const double d = gasLength_ * std::pow(rng.uniform(), 1.5), side = rng.uniform() < 0.5 ? -1.0 : 1.0;
    q.p = glm::dvec3(side * (half_.x + d), rng.range(-half_.y, half_.y), rng.range(-half_.z, half_.z));
    q.t = 0.55 + 0.4 * std::sqrt(d / gasLength_) + 0.05 * rng.jitter();
    q.size = 0.75;
    return q;
  }

  uint64_t gas_ = 0, block_ = 0, k_ = 1, capacity_ = 0;
  glm::dvec3 half_{0};
  double gasLength_ = 0;
};

// ---- particles-drops -------------------------------------------------------------------------------

class DropsScene final : public SceneBase {
public:
  DropsScene(uint64_t n, uint64_t seed, float radius) : SceneBase(seed, 0x64726f7073ull, radius) {
    liquid_ = n - n / 20;
    // Layout in a unit box centered on 0, scaled at the end so the liquid has kLiquidDensity.
    Rng rng = layoutRng();
    for (int j = 0; j < 48; ++j) {
      Object o;
      o.a = glm::dvec3(rng.range(-0.4, 0.4), rng.range(-0.4, 0.4), rng.range(-0.4, 0.4));
      const double u = rng.uniform();
      o.r = 0.02 + 0.1 * u * u * u; // many small droplets, a few large ones
      o.speed = rng.uniform();
      objects_.push_back(o);
    }
    for (int j = 0; j < 16; ++j) { // ligaments: droplet j to its nearest neighbor
      const Object& from = objects_[size_t(j)];
      size_t nearest = 0;
      double best = 1e30;
      for (size_t k = 0; k < 48; ++k) {
        const double d = glm::length(objects_[k].a - from.a);
        if (k != size_t(j) && d < best) best = d, nearest = k;
      }
      Object o;
      o.filament = true;
      o.a = from.a;
      o.b = objects_[nearest].a;
      o.r = 0.3 * std::min(from.r, objects_[nearest].r);
      o.speed = rng.range(0.65, 0.95); // stretched liquid moves fastest
      objects_.push_back(o);
    }
    std::vector<double> volumes;
    for (const Object& o : objects_)
      volumes.push_back(o.filament ? kPi * o.r * o.r * glm::length(o.b - o.a)
                                   : 4.0 / 3.0 * kPi * o.r * o.r * o.r);
    const double volume = std::accumulate(volumes.begin(), volumes.end(), 0.0);
    const double s = std::cbrt(std::max<double>(1, double(liquid_)) / (kLiquidDensity * volume));
    for (Object& o : objects_) {
      o.a *= s;
      o.b *= s;
      o.r *= s;
      if (o.filament) { // an orthonormal frame around the axis, for points on the cross-section
        const glm::dvec3 axis = glm::normalize(o.b - o.a);
        o.e1 = glm::normalize(
            glm::cross(axis, std::abs(axis.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0)));
        o.e2 = glm::cross(axis, o.e1);
      }
    }
    boxHalf_ = 0.5 * s;
    offsets_ = apportion(volumes, liquid_);
  }

private:
  static constexpr double kLiquidDensity = 0.9;

  struct Object {
    glm::dvec3 a{0}, b{0}; // sphere: center a; filament: axis from a to b
    glm::dvec3 e1{0}, e2{0};
    double r = 0, speed = 0;
    bool filament = false;
  };

  Particle particle(uint64_t i) const override {
    Rng rng(key_, i);
    Particle q;
    if (i < liquid_) {
      const Object& o = objects_[objectOf(offsets_, i)];
      if (o.filament) {
        const double along = rng.uniform(), rho = o.r * std::sqrt(rng.uniform()),
                     phi = 2 * kPi * rng.uniform();
        q.p = o.a + (o.b - o.a) * along + rho * (std::cos(phi) * o.e1 + std::sin(phi) * o.e2);
        q.t = 0.1 + 0.45 * o.speed;
      } else {
        const glm::dvec3 d = rng.inBall();
        const double r2 = glm::dot(d, d);
        q.p = o.a + o.r * d;
        q.t = 0.1 + 0.45 * o.speed + 0.12 * r2 * r2 * r2; // the surface is warmer
      }
      q.size = 1 + 0.04 * rng.jitter();
      return q;
    }
    // Vapor: uniform in the box, outside the droplets (a particle still inside after a few tries is
    // hidden by the liquid).
    for (int tries = 0; tries < 4; ++tries) {
      q.p = glm::dvec3(rng.range(-1, 1), rng.range(-1, 1), rng.range(-1, 1)) * boxHalf_;
      bool inside = false;
      for (const Object& o : objects_)
        if (!o.filament && glm::dot(q.p - o.a, q.p - o.a) < o.r * o.r) inside = true;
      if (!inside) break;
    }
    q.t = 0.7 + 0.3 * rng.uniform();
    q.size = 0.7;
    return q;
  }

  uint64_t liquid_ = 0;
  double boxHalf_ = 0;
  std::vector<Object> objects_;
  std::vector<uint64_t> offsets_;
};

// ---- particles-laser -------------------------------------------------------------------------------

class LaserScene final : public SceneBase {
public:
  LaserScene(uint64_t n, uint64_t seed, float radius) : SceneBase(seed, 0x6c61736572ull, radius) {
    const uint64_t plume = n / 8;
    vapor_ = plume / 5;
    slab_ = n - plume;
    // The smallest slab width with room for every slab particle (capacity grows about as w^3).
    w_ = std::max<int64_t>(1, int64_t(std::cbrt(double(slab_))) - 2);
    while (layoutSlab(w_) < slab_)
      ++w_;
    const double width = double(w_) * kCell;
    craterRadius_ = kCraterRadius * width;
    // The plume: a cone above the crater, as tall as 1.5 slab widths.
    height_ = 1.5 * width;
    Rng rng = layoutRng();
    std::vector<double> weights;
    for (int j = 0; j < 256; ++j) {
      Cluster c;
      c.heightFraction = std::pow(rng.uniform(), 0.8);
      c.center = coneSample(rng, 2.0 + height_ * c.heightFraction);
      const double u = rng.uniform();
      weights.push_back(0.05 + u * u * u * u); // mostly small clusters, a few large droplets
      clusters_.push_back(c);
    }
    clusterOffsets_ = apportion(weights, plume - vapor_);
    for (size_t j = 0; j < clusters_.size(); ++j) // density 1: the radius follows from the count
      clusters_[j].radius =
          std::cbrt(double(clusterOffsets_[j + 1] - clusterOffsets_[j]) / (4.0 / 3.0 * kPi));
  }

private:
  static constexpr double kCell = 1.4142135623730951; // fcc cell edge for nearest neighbors at 1
  static constexpr double kCraterRadius = 0.3;        // of the slab width
  static constexpr double kBasis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};

  struct Cluster {
    glm::dvec3 center{0};
    double radius = 0, heightFraction = 0;
  };

  // Fills columnStart_ for a slab of w x w cells, depth max(2, w/4) cells, with a paraboloid crater of
  // radius 0.3 w and depth 0.45 x the slab's at the center; returns the number of atom sites.
  uint64_t layoutSlab(int64_t w) {
    depth_ = std::max<int64_t>(2, w / 4);
    const double rc = kCraterRadius * double(w);
    columnStart_.assign(size_t(w * w + 1), 0);
    for (int64_t c = 0; c < w * w; ++c) {
      const double dx = double(c % w) + 0.5 - w / 2.0, dy = double(c / w) + 0.5 - w / 2.0;
      const double r2 = (dx * dx + dy * dy) / (rc * rc);
      const int64_t crater = r2 < 1 ? int64_t(0.45 * double(depth_) * (1 - r2)) : 0;
      columnStart_[size_t(c + 1)] = columnStart_[size_t(c)] + 4 * uint64_t(depth_ - crater);
    }
    return columnStart_.back();
  }

  glm::dvec3 coneSample(Rng& rng, double z) const {
    const double rho = (0.35 * craterRadius_ + std::tan(30 * kPi / 180) * z) * std::sqrt(rng.uniform());
    const double phi = 2 * kPi * rng.uniform();
    return {rho * std::cos(phi), rho * std::sin(phi), z};
  }

  Particle particle(uint64_t i) const override {
    Rng rng(key_, i);
    Particle q;
    if (i < slab_) {
      const uint64_t s = thinnedSite(i, columnStart_.back(), slab_);
      const size_t column = objectOf(columnStart_, s);
      const uint64_t k = s - columnStart_[column],
                     height = (columnStart_[column + 1] - columnStart_[column]) / 4;
      const double* b = kBasis[k % 4];
      const double cz = double(k / 4) + b[2];
      const glm::dvec3 site((double(int64_t(column) % w_) + b[0] - w_ / 2.0) * kCell,
                            (double(int64_t(column) / w_) + b[1] - w_ / 2.0) * kCell,
                            (cz - double(depth_)) * kCell);
      // Molten near the crater: heat falls off with the distance from the laser axis and the depth below
      // the column's surface.
      const double axis2 = (site.x * site.x + site.y * site.y) / (craterRadius_ * craterRadius_);
      const double melt = std::exp(-axis2) * std::exp(-(double(height) - cz) / 1.5);
      q.p = site + (0.04 + 0.35 * melt) * rng.jitter3();
      q.t = 0.1 + 0.6 * melt + 0.03 * rng.jitter();
      q.size = 1 + 0.03 * rng.jitter();
    } else if (i < clusterOffsets_.back() + slab_) {
      const Cluster& c = clusters_[objectOf(clusterOffsets_, i - slab_)];
      q.p = c.center + c.radius * rng.inBall();
      q.t = 0.5 + 0.4 * c.heightFraction + 0.05 * rng.jitter(); // higher clusters flew faster
      q.size = 1 + 0.03 * rng.jitter();
    } else {
      q.p = coneSample(rng, height_ * rng.uniform());
      q.t = 0.85 + 0.15 * rng.uniform();
      q.size = 0.8;
    }
    return q;
  }

  uint64_t slab_ = 0, vapor_ = 0;
  int64_t w_ = 1, depth_ = 2;
  double craterRadius_ = 0, height_ = 0;
  std::vector<uint64_t> columnStart_; // first site of each column (x fastest), then the total
  std::vector<Cluster> clusters_;
  std::vector<uint64_t> clusterOffsets_;
};

// ---- particles-uniform -----------------------------------------------------------------------------

class UniformScene final : public SceneBase {
public:
  UniformScene(uint64_t n, uint64_t seed, float radius)
      : SceneBase(seed, 0x756e69666f726dull, radius), side_(std::cbrt(double(n))) {}

private:
  Particle particle(uint64_t i) const override {
    Rng rng(key_, i);
    Particle q;
    q.p = glm::dvec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * side_;
    q.t = glm::length(q.p) / (0.5 * side_ * std::sqrt(3.0)); // center to corner
    q.size = 0.5 + rng.uniform();
    return q;
  }

  double side_;
};

} // namespace

std::unique_ptr<ParticleGenerator> makeParticleGenerator(ParticleScene scene, uint64_t particles,
                                                         uint64_t seed, float radius) {
  switch (scene) {
  case ParticleScene::Block:
    return std::make_unique<BlockScene>(particles, seed, radius);
  case ParticleScene::Drops:
    return std::make_unique<DropsScene>(particles, seed, radius);
  case ParticleScene::Laser:
    return std::make_unique<LaserScene>(particles, seed, radius);
  case ParticleScene::Uniform:
    break;
  }
  return std::make_unique<UniformScene>(particles, seed, radius);
}

} // namespace pointrast::detail
