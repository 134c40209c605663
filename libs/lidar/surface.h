// Local surface of a scan: normals and planarity from the PCA of each point's neighbourhood,
// and the IMLS-SLAM sampling (Deschaud 2018, Sec. V) that picks the points which best
// constrain each of the six motion directions.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace jvl::lidar {

struct SurfaceOptions {
  int normal_neighbors = 12;     // k nearest points used for the PCA.
  double normal_radius = 1.0;    // m, neighbours further away are ignored.
  int min_normal_neighbors = 6;  // fewer -> no normal; the point is not used.
  void Check() const;
};

struct ScanSurface {
  std::vector<Eigen::Vector3d> points;   // Scan (cam0) frame.
  std::vector<Eigen::Vector3d> normals;  // Unit, oriented towards the sensor; zero if invalid.
  std::vector<double> planarity;  // a2D = (s2 - s3) / s1, s_i = sqrt(lambda_i); 0 if invalid.
  std::vector<uint8_t> valid;
  size_t size() const { return points.size(); }
};

// Normals and planarity of every point, from the covariance of its k nearest neighbours.
ScanSurface ComputeSurface(const std::vector<Eigen::Vector3d>& points,
                           const SurfaceOptions& options, int threads);

// The nine sampling lists of IMLS-SLAM: a2D^2 (p x n).(+x, -x, +y, -y, +z, -z) (rotations about
// the axes) and a2D^2 |n.x|, |n.y|, |n.z| (translations along them), each holding the indices
// of the valid points sorted by decreasing value (ties: lower index first). Only the first
// max_length entries of each list are kept (0 = all); sampling rarely looks further.
std::array<std::vector<int>, 9> SamplingLists(const ScanSurface& surface, size_t max_length = 0);

// Takes up to `per_list` points from each list, in list order, for which accept(i) is true
// (IMLS-SLAM: the point has a model neighbour within r at the predicted pose). A point already
// taken by an earlier list is skipped. Returns indices in selection order.
template <typename Accept>
std::vector<int> SelectSamples(const std::array<std::vector<int>, 9>& lists, size_t n_points,
                               int per_list, Accept&& accept) {
  std::vector<uint8_t> taken(n_points, 0);
  std::vector<int> samples;
  for (const std::vector<int>& list : lists) {
    int count = 0;
    for (const int i : list) {
      if (count >= per_list) break;
      if (taken[i]) continue;
      if (!accept(i)) continue;
      taken[i] = 1;
      samples.push_back(i);
      ++count;
    }
  }
  return samples;
}

}  // namespace jvl::lidar
