#include "lidar/surface.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/check.h"
#include "core/threads.h"
#include "lidar/voxel_grid.h"

namespace jvl::lidar {
namespace {

// Local PCA of point i's neighbourhood nn[0, count): normal = eigenvector of the smallest
// eigenvalue, planarity a2D = (s2 - s3) / s1 (IMLS-SLAM Sec. V). The covariance is summed in six
// scalars (the same products and sums as the outer products d d^T, which the compiler spilled
// through the stack on every neighbour).
void FitLocalPlane(const std::vector<Eigen::Vector3d>& points, const std::pair<double, int>* nn,
                   size_t count, int i, ScanSurface* s) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t j = 0; j < count; ++j) mean += points[nn[j].second];
  mean /= static_cast<double>(count);
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  for (size_t j = 0; j < count; ++j) {
    const Eigen::Vector3d& p = points[nn[j].second];
    const double dx = p.x() - mean.x(), dy = p.y() - mean.y(), dz = p.z() - mean.z();
    xx += dx * dx, xy += dx * dy, xz += dx * dz;
    yy += dy * dy, yz += dy * dz, zz += dz * dz;
  }
  Eigen::Matrix3d cov;
  cov << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  cov /= static_cast<double>(count);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  // Eigenvalues ascending: lambda3 <= lambda2 <= lambda1.
  const Eigen::Vector3d l = eig.eigenvalues().cwiseMax(0.0);
  const double s1 = std::sqrt(l[2]), s2 = std::sqrt(l[1]), s3 = std::sqrt(l[0]);
  if (!(s1 > 0)) return;
  Eigen::Vector3d n = eig.eigenvectors().col(0).normalized();
  if (n.dot(points[i]) > 0) n = -n;  // Towards the sensor at the origin.
  s->normals[i] = n;
  s->planarity[i] = (s2 - s3) / s1;
  s->valid[i] = 1;
}

}  // namespace

void SurfaceOptions::Check() const {
  JVL_CHECK(normal_neighbors >= 3, "normal_neighbors must be >= 3, got " << normal_neighbors);
  JVL_CHECK(normal_radius > 0, "normal_radius must be > 0, got " << normal_radius);
  JVL_CHECK(min_normal_neighbors >= 3 && min_normal_neighbors <= normal_neighbors,
            "min_normal_neighbors must be in [3, normal_neighbors], got " << min_normal_neighbors);
}

ScanSurface ComputeSurface(const std::vector<Eigen::Vector3d>& points,
                           const SurfaceOptions& options, int threads) {
  ScanSurface s;
  s.points = points;
  s.normals.assign(points.size(), Eigen::Vector3d::Zero());
  s.planarity.assign(points.size(), 0.0);
  s.valid.assign(points.size(), 0);
  if (points.empty()) return s;
  const PointGrid grid(points, options.normal_radius);
  const double r2 = options.normal_radius * options.normal_radius;
  const size_t k = static_cast<size_t>(options.normal_neighbors);
  grid.ForEachCell(threads, [&](const std::vector<int>& members, const std::vector<int>& cand) {
    // Candidate coordinates copied once per cell, one array per axis: the distances of all
    // candidates to a member are then computed in one vectorised pass (the same arithmetic as
    // (q - p).squaredNorm(): (dx^2 + dy^2) + dz^2).
    const size_t n = cand.size();
    std::vector<double> xs(n), ys(n), zs(n), d2(n);
    for (size_t c = 0; c < n; ++c) {
      xs[c] = points[cand[c]].x();
      ys[c] = points[cand[c]].y();
      zs[c] = points[cand[c]].z();
    }
    // The k nearest, sorted by (distance, index), as a fixed array filled field by field.
    std::vector<std::pair<double, int>> nn(k);
    for (const int i : members) {
      const double px = points[i].x(), py = points[i].y(), pz = points[i].z();
      for (size_t c = 0; c < n; ++c) {
        const double dx = xs[c] - px, dy = ys[c] - py, dz = zs[c] - pz;
        d2[c] = dx * dx + dy * dy + dz * dz;
      }
      // The k nearest within the radius, kept sorted by (distance, index) - a strict order, so
      // the set is deterministic - by insertion (k is small; cheaper than a partition).
      size_t count = 0;
      for (size_t c = 0; c < n; ++c) {
        const double d = d2[c];
        if (d > r2) continue;
        const int index = cand[c];
        auto before = [&](const std::pair<double, int>& e) {
          return d < e.first || (d == e.first && index < e.second);
        };
        if (count == k) {
          if (!before(nn[k - 1])) continue;
          --count;
        }
        // Into place from the back (mostly few steps: the nearer cells come first).
        size_t m = count++;
        for (; m > 0 && before(nn[m - 1]); --m) nn[m] = nn[m - 1];
        nn[m].first = d;
        nn[m].second = index;
      }
      if (count < static_cast<size_t>(options.min_normal_neighbors)) continue;
      FitLocalPlane(points, nn.data(), count, i, &s);
    }
  });
  return s;
}

std::array<std::vector<int>, 9> SamplingLists(const ScanSurface& surface, size_t max_length) {
  std::vector<int> valid;
  for (size_t i = 0; i < surface.size(); ++i) {
    if (surface.valid[i]) valid.push_back(static_cast<int>(i));
  }
  std::array<std::vector<int>, 9> lists;
  std::vector<double> value(surface.size());
  for (int k = 0; k < 9; ++k) {
    for (const int i : valid) {
      const Eigen::Vector3d& p = surface.points[i];
      const Eigen::Vector3d& n = surface.normals[i];
      const double a2 = surface.planarity[i] * surface.planarity[i];
      if (k < 6) {
        // Rotation about axis k/2 in the sign given by k%2.
        const double sign = (k % 2 == 0) ? 1.0 : -1.0;
        value[i] = a2 * sign * p.cross(n)[k / 2];
      } else {
        value[i] = a2 * std::abs(n[k - 6]);
      }
    }
    lists[k] = valid;
    const size_t keep = max_length == 0 ? valid.size() : std::min(max_length, valid.size());
    if (keep == 0) continue;
    const auto before = [&](int a, int b) {
      return value[a] > value[b] || (value[a] == value[b] && a < b);
    };
    auto& list = lists[k];
    std::nth_element(list.begin(), list.begin() + static_cast<std::ptrdiff_t>(keep) - 1, list.end(),
                     before);
    list.resize(keep);
    std::sort(list.begin(), list.end(), before);
  }
  return lists;
}

}  // namespace jvl::lidar
