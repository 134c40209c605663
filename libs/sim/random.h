// Portable, seedable randomness for the simulator: a SplitMix64 generator (same sequence on every
// platform and standard library, unlike std::normal_distribution) and hash-based value noise for
// procedural textures.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

namespace jvl::sim {

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix.
inline uint64_t Mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

inline uint64_t HashCombine(uint64_t a, uint64_t b) { return Mix64(a ^ Mix64(b)); }

// Uniform [0, 1) from a hash of three integers (lattice values of the noise functions).
inline double HashUnit(int64_t a, int64_t b, uint64_t seed) {
  const uint64_t h =
      HashCombine(HashCombine(seed, static_cast<uint64_t>(a)), static_cast<uint64_t>(b));
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(Mix64(seed)) {}
  uint64_t Next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * (1.0 / 9007199254740992.0); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Integer in [lo, hi].
  int UniformInt(int lo, int hi) {
    return lo + static_cast<int>(Uniform() * static_cast<double>(hi - lo + 1));
  }
  bool Bernoulli(double p) { return Uniform() < p; }
  // Standard normal by Box-Muller (one value per call; the pair's second value is discarded so
  // that the stream position depends only on the number of calls).
  double Normal() {
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }
  double Normal(double sigma) { return sigma * Normal(); }

 private:
  uint64_t state_;
};

// Fast approximately normal samples for per-pixel and per-return noise: 4096 fixed
// Box-Muller values (standardised to mean 0, variance 1) indexed by 12 random bits.
class NormalTable {
 public:
  NormalTable() : values_(4096) {
    Rng rng(0x4e6f726d616cULL);
    double mean = 0, var = 0;
    for (double& v : values_) mean += (v = rng.Normal());
    mean /= values_.size();
    for (double& v : values_) var += (v - mean) * (v - mean);
    const double scale = 1.0 / std::sqrt(var / values_.size());
    for (double& v : values_) v = (v - mean) * scale;
  }
  double Sample(Rng& rng) const { return values_[rng.Next() >> 52]; }

 private:
  std::vector<double> values_;
};

// Uniform [0, 1) at lattice point (a, b) for a key from Mix64(seed): one mix per value instead
// of the four of HashUnit. The noise functions below evaluate several lattice values for every
// shaded ray, so this hash is the simulator's hottest code.
inline double LatticeUnit(int64_t a, int64_t b, uint64_t key) {
  const uint64_t h = Mix64(key ^ (static_cast<uint64_t>(a) * 0x9e3779b97f4a7c15ULL) ^
                           (static_cast<uint64_t>(b) * 0xc2b2ae3d27d4eb4fULL));
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

// Smooth 2-D value noise in [0, 1] (bilinear over hashed lattice values, smoothstep weights).
inline double ValueNoise(double x, double y, uint64_t seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int64_t ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  double tx = x - fx, ty = y - fy;
  tx = tx * tx * (3.0 - 2.0 * tx);
  ty = ty * ty * (3.0 - 2.0 * ty);
  const uint64_t key = Mix64(seed);
  const double a = LatticeUnit(ix, iy, key), b = LatticeUnit(ix + 1, iy, key);
  const double c = LatticeUnit(ix, iy + 1, key), d = LatticeUnit(ix + 1, iy + 1, key);
  const double bottom = a + (b - a) * tx;
  return bottom + ((c + (d - c) * tx) - bottom) * ty;
}

}  // namespace jvl::sim
