#include "direction/mean_shift.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "core/check.h"

namespace jvl::direction {
namespace {

// Points in a uniform grid of cell = kernel support, so a neighbourhood query visits the 3^D
// cells around a point. Cells keep their points in index order (deterministic sums).
template <int D>
class Grid {
 public:
  using Vec = Eigen::Matrix<double, D, 1>;
  Grid(const std::vector<Vec>& points, double cell) : points_(points), cell_(cell) {
    for (size_t i = 0; i < points.size(); ++i) cells_[Key(Cell(points[i]))].push_back(int(i));
  }
  // Calls fn(index) for every point in the cells touching p, in a fixed cell order.
  template <typename Fn>
  void ForNeighbours(const Vec& p, Fn&& fn) const {
    const Eigen::Matrix<int64_t, D, 1> c = Cell(p);
    const int n = D == 2 ? 9 : 27;
    for (int k = 0; k < n; ++k) {
      Eigen::Matrix<int64_t, D, 1> q = c;
      int r = k;
      for (int d = 0; d < D; ++d, r /= 3) q[d] += r % 3 - 1;
      const auto it = cells_.find(Key(q));
      if (it == cells_.end()) continue;
      for (int i : it->second) fn(i);
    }
  }

 private:
  Eigen::Matrix<int64_t, D, 1> Cell(const Vec& p) const {
    Eigen::Matrix<int64_t, D, 1> c;
    for (int d = 0; d < D; ++d) c[d] = static_cast<int64_t>(std::floor(p[d] / cell_));
    return c;
  }
  static uint64_t Key(const Eigen::Matrix<int64_t, D, 1>& c) {
    uint64_t key = 1469598103934665603ull;
    for (int d = 0; d < D; ++d) key = (key ^ static_cast<uint64_t>(c[d])) * 1099511628211ull;
    return key;
  }
  const std::vector<Vec>& points_;
  double cell_;
  std::unordered_map<uint64_t, std::vector<int>> cells_;  // Hash collisions only add work.
};

// Distance used by the kernel. On the sphere the chord |a - b| = 2 sin(theta / 2) stands in for
// the angle theta (they agree to 1 % below 20 deg): exp(-|a-b|^2 / 2h^2) is the von Mises-Fisher
// kernel exp(kappa (cos theta - 1)) with kappa = 1 / h^2, and costs no trigonometry.
template <int D>
double Distance(const Eigen::Matrix<double, D, 1>& a, const Eigen::Matrix<double, D, 1>& b) {
  return (a - b).norm();
}

// Seeds: the normalised mean of the points of each cell of size seed_bin * h, in the order of
// the first point of each cell; every point takes the label of its seed (bin seeding). With
// seed_bin == 0 every point is its own seed.
template <int D>
std::vector<int> Seeds(const std::vector<Eigen::Matrix<double, D, 1>>& points, double bin,
                       std::vector<Eigen::Matrix<double, D, 1>>* seeds) {
  std::vector<int> seed_of(points.size());
  if (bin <= 0) {
    *seeds = points;
    for (size_t i = 0; i < points.size(); ++i) seed_of[i] = int(i);
    return seed_of;
  }
  std::unordered_map<uint64_t, int> index;
  std::vector<int> counts;
  for (size_t i = 0; i < points.size(); ++i) {
    uint64_t key = 1469598103934665603ull;
    for (int d = 0; d < D; ++d)
      // Through int64_t: a negative double converted to uint64_t directly is undefined.
      key = (key ^ static_cast<uint64_t>(static_cast<int64_t>(std::floor(points[i][d] / bin)))) *
            1099511628211ull;
    const auto [it, inserted] = index.emplace(key, int(seeds->size()));
    if (inserted) {
      seeds->push_back(Eigen::Matrix<double, D, 1>::Zero());
      counts.push_back(0);
    }
    (*seeds)[it->second] += points[i];
    ++counts[it->second];
    seed_of[i] = it->second;
  }
  for (size_t k = 0; k < seeds->size(); ++k) (*seeds)[k] /= counts[k];
  return seed_of;
}

template <int D>
MeanShiftResult Run(const std::vector<Eigen::Matrix<double, D, 1>>& points,
                    const MeanShiftOptions& options, bool sphere) {
  using Vec = Eigen::Matrix<double, D, 1>;
  options.Check();
  const double h = options.bandwidth;
  // Kernel support as a chord (sphere) or a distance (plane).
  const double support = sphere ? 2.0 * std::sin(std::min(options.truncation * h, M_PI) / 2.0)
                                : options.truncation * h;
  const Grid<D> grid(points, support + 1e-12);
  std::vector<Vec> seeds;
  const std::vector<int> seed_of = Seeds<D>(points, options.seed_bin * h, &seeds);
  MeanShiftResult result;
  std::vector<Vec> modes;
  std::vector<int> seed_label(seeds.size(), -1);
  for (size_t s = 0; s < seeds.size(); ++s) {
    Vec m = seeds[s];
    if (sphere) m.normalize();
    for (int it = 0; it < options.max_iterations; ++it) {
      Vec sum = Vec::Zero();
      double wsum = 0;
      grid.ForNeighbours(m, [&](int j) {
        const double dist = Distance<D>(m, points[j]);
        if (dist > support) return;
        const double w = std::exp(-0.5 * dist * dist / (h * h));
        sum += w * points[j];
        wsum += w;
      });
      ++result.total_iterations;
      if (wsum <= 0) break;
      Vec next = sum / wsum;
      if (sphere) {
        if (next.norm() < 1e-12) break;  // Antipodal tie: keep the current estimate.
        next.normalize();
      }
      const double step = Distance<D>(m, next);
      m = next;
      if (step < options.tolerance * h) break;
    }
    // Merge with the first earlier mode within the merge radius (seed order).
    int label = -1;
    for (size_t k = 0; k < modes.size() && label < 0; ++k) {
      if (Distance<D>(modes[k], m) < options.merge_radius * h) label = int(k);
    }
    if (label < 0) {
      label = int(modes.size());
      modes.push_back(m);
    }
    seed_label[s] = label;
  }
  result.sizes.assign(modes.size(), 0);
  result.labels.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    result.labels[i] = seed_label[seed_of[i]];
    ++result.sizes[result.labels[i]];
  }
  for (const Vec& m : modes) {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    v.head<D>() = m;
    result.modes.push_back(v);
  }
  return result;
}

}  // namespace

void MeanShiftOptions::Check() const {
  JVL_CHECK(std::isfinite(bandwidth) && bandwidth > 0,
            "mean-shift bandwidth must be positive (got " << bandwidth << ")");
  JVL_CHECK(truncation >= 1.0, "mean-shift truncation must be >= 1 (got " << truncation << ")");
  JVL_CHECK(max_iterations >= 1, "mean-shift max_iterations must be >= 1");
  JVL_CHECK(tolerance > 0 && merge_radius > 0, "mean-shift tolerance and merge_radius must be > 0");
  JVL_CHECK(seed_bin >= 0 && seed_bin <= 1,
            "mean-shift seed_bin must be in [0, 1] (got " << seed_bin << ")");
}

MeanShiftResult MeanShiftSphere(const std::vector<Eigen::Vector3d>& directions,
                                const MeanShiftOptions& options) {
  std::vector<Eigen::Vector3d> unit;
  unit.reserve(directions.size());
  for (const auto& d : directions) {
    JVL_CHECK(d.allFinite() && d.norm() > 1e-12, "mean-shift: direction is zero or not finite");
    unit.push_back(d.normalized());
  }
  return Run<3>(unit, options, /*sphere=*/true);
}

MeanShiftResult MeanShiftPlane(const std::vector<Eigen::Vector2d>& points,
                               const MeanShiftOptions& options) {
  for (const auto& p : points) JVL_CHECK(p.allFinite(), "mean-shift: point is not finite");
  return Run<2>(points, options, /*sphere=*/false);
}

}  // namespace jvl::direction
