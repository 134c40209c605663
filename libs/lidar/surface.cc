#include "lidar/surface.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/check.h"
#include "core/threads.h"
#include "lidar/voxel_grid.h"

namespace jvl::lidar {

void SurfaceOptions::Check() const {
  JVL_CHECK(normal_neighbors >= 3, "--normal-neighbors must be >= 3, got " << normal_neighbors);
  JVL_CHECK(normal_radius > 0, "--normal-radius must be > 0, got " << normal_radius);
  JVL_CHECK(min_normal_neighbors >= 3 && min_normal_neighbors <= normal_neighbors,
            "--min-normal-neighbors must be in [3, --normal-neighbors], got "
                << min_normal_neighbors);
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
  constexpr int64_t kChunk = 512;
  const int64_t chunks = (static_cast<int64_t>(points.size()) + kChunk - 1) / kChunk;
  ParallelFor(chunks, threads, [&](int64_t chunk) {
    std::vector<std::pair<double, int>> nn;
    const size_t end = std::min(points.size(), static_cast<size_t>((chunk + 1) * kChunk));
    for (size_t i = static_cast<size_t>(chunk * kChunk); i < end; ++i) {
      grid.RadiusSearch(points[i], options.normal_radius,
                        static_cast<size_t>(options.normal_neighbors), &nn);
      if (static_cast<int>(nn.size()) < options.min_normal_neighbors) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const auto& [d2, j] : nn) mean += points[j];
      mean /= static_cast<double>(nn.size());
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (const auto& [d2, j] : nn) {
        const Eigen::Vector3d d = points[j] - mean;
        cov += d * d.transpose();
      }
      cov /= static_cast<double>(nn.size());
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
      // Eigenvalues ascending: lambda3 <= lambda2 <= lambda1.
      const Eigen::Vector3d l = eig.eigenvalues().cwiseMax(0.0);
      const double s1 = std::sqrt(l[2]), s2 = std::sqrt(l[1]), s3 = std::sqrt(l[0]);
      if (!(s1 > 0)) continue;
      Eigen::Vector3d n = eig.eigenvectors().col(0);
      if (n.dot(points[i]) > 0) n = -n;  // Towards the sensor at the origin.
      s.normals[i] = n;
      s.planarity[i] = (s2 - s3) / s1;
      s.valid[i] = 1;
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
    std::partial_sort(lists[k].begin(), lists[k].begin() + keep, lists[k].end(),
                      [&](int a, int b) { return value[a] > value[b] || (value[a] == value[b] && a < b); });
    lists[k].resize(keep);
  }
  return lists;
}

}  // namespace jvl::lidar
