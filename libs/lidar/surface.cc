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

// Local PCA of point i's neighbourhood: normal = eigenvector of the smallest eigenvalue,
// planarity a2D = (s2 - s3) / s1 (IMLS-SLAM Sec. V).
void FitLocalPlane(const std::vector<Eigen::Vector3d>& points,
                   const std::vector<std::pair<double, int>>& nn, int i, ScanSurface* s) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& e : nn) mean += points[e.second];
  mean /= static_cast<double>(nn.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& e : nn) {
    const Eigen::Vector3d d = points[e.second] - mean;
    cov += d * d.transpose();
  }
  cov /= static_cast<double>(nn.size());
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
    std::vector<std::pair<double, int>> nn;
    for (const int i : members) {
      const double px = points[i].x(), py = points[i].y(), pz = points[i].z();
      for (size_t c = 0; c < n; ++c) {
        const double dx = xs[c] - px, dy = ys[c] - py, dz = zs[c] - pz;
        d2[c] = dx * dx + dy * dy + dz * dz;
      }
      // The k nearest within the radius, kept sorted by (distance, index) - a strict order, so
      // the set is deterministic - by insertion (k is small; cheaper than a partition).
      nn.clear();
      for (size_t c = 0; c < n; ++c) {
        if (d2[c] > r2) continue;
        const std::pair<double, int> e(d2[c], cand[c]);
        if (nn.size() == k) {
          if (!(e < nn.back())) continue;
          nn.pop_back();
        }
        // Into place from the back (mostly few steps: the nearer cells come first).
        nn.push_back(e);
        for (size_t m = nn.size() - 1; m > 0 && e < nn[m - 1]; --m) std::swap(nn[m], nn[m - 1]);
      }
      if (nn.size() < static_cast<size_t>(options.min_normal_neighbors)) continue;
      FitLocalPlane(points, nn, i, &s);
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
