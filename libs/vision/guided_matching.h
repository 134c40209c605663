// Descriptor matching guided by known camera poses (Sec. 4.1: the prior poses replace the
// tracking of ORB-SLAM2, so every search below uses them instead of an estimated motion):
//  - MatchByProjection: map points projected into a frame are matched to keypoints in a window
//    scaled by the predicted octave (ORB-SLAM2's SearchByProjection).
//  - MatchEpipolar: keypoints of two keyframes are matched along the epipolar line given by the
//    relative pose (ORB-SLAM2's SearchForTriangulation, here without a vocabulary).
// Both apply a Hamming threshold, Lowe's ratio test and the rotation-histogram consistency check.
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "vision/orb_features.h"

namespace jvl::vision {

// Buckets keypoints on a regular grid for window queries.
class KeypointGrid {
 public:
  KeypointGrid(const std::vector<OrbKeypoint>& keypoints, int width, int height, int cell = 16);
  // Keypoints within `radius` px of uv (square window, as ORB-SLAM) with octave in
  // [min_octave, max_octave], in increasing index order.
  std::vector<int> InWindow(const Eigen::Vector2d& uv, double radius, int min_octave,
                            int max_octave) const;
  // Keypoints in the grid cells that the band of half-width `band` px around the image line
  // l = (a, b, c) (a u + b v + c = 0) crosses: a superset of the keypoints within `band` of it,
  // each listed once, cell by cell.
  // Only the part of the line whose coordinate along the walking axis lies in [lo, hi] (pixels)
  // is visited.
  void NearLine(const Eigen::Vector3d& line, double band, std::vector<int>* out, double lo = -1e300,
                double hi = 1e300) const;

 private:
  const std::vector<OrbKeypoint>* keypoints_;
  int cell_, nx_, ny_;
  std::vector<std::vector<int>> cells_;
};

// Keeps matches whose orientation change falls in the three most populated bins of a histogram
// (ORB-SLAM2's rotation consistency check). angle_diff_deg[i] = angle in new - angle in old.
std::vector<bool> RotationConsistent(const std::vector<float>& angle_diff_deg, int bins = 30);

struct ProjectionMatchOptions {
  double window_px = 4.0;  // Search radius at level 0; multiplied by the level scale.
  int max_distance = 100;  // Hamming threshold (ORB-SLAM2 TH_HIGH).
  double ratio = 0.8;      // Best/second-best ratio (applied when both are on one level).
  bool check_orientation = true;
  void Check() const;
};

// A map point predicted in a frame.
struct ProjectedPoint {
  Eigen::Vector2d uv;
  int predicted_octave = 0;
  Descriptor descriptor{};
  float reference_angle = 0;  // Keypoint angle of the observation the descriptor comes from.
};

// Returns, per projected point, the matched keypoint index or -1. Keypoints with taken[k] set are
// skipped (taken may be empty). A keypoint is given to at most one point (the closest).
std::vector<int> MatchByProjection(const std::vector<ProjectedPoint>& points,
                                   const OrbFeatures& frame, const KeypointGrid& grid,
                                   const std::vector<double>& level_scales,
                                   const ProjectionMatchOptions& options,
                                   const std::vector<bool>& taken = {});

struct EpipolarMatchOptions {
  int max_distance = 50;          // Hamming threshold (ORB-SLAM2 TH_LOW).
  double ratio = 0.8;             // Best/second-best ratio among candidates on the line.
  double epipolar_chi2 = 3.84;    // chi2(1 dof, 95%) times the level variance.
  double min_epipole_px = 10.0;   // Keypoints this close to the epipole (x sqrt(level scale)) skip.
  int max_octave_difference = 2;  // Candidates on levels further apart are not compared.
  double min_depth = 1.0;         // m in view 1: the searched segment starts at this depth.
  bool check_orientation = true;
  void Check() const;
};

// Epipolar-constrained matching of unused keypoints of frame 1 to unused keypoints of frame 2.
// Only the segment of the epipolar line that corresponds to depths in [min_depth, inf) in view 1
// with positive depth in view 2 is searched.
// used1/used2 may be empty. Returns (index in 1, index in 2) pairs ordered by index in 1.
std::vector<std::pair<int, int>> MatchEpipolar(
    const PinholeCamera& camera, const OrbFeatures& f1, const Rigid3d& cam1_from_world,
    const std::vector<bool>& used1, const OrbFeatures& f2, const Rigid3d& cam2_from_world,
    const std::vector<bool>& used2, const std::vector<double>& level_scales,
    const EpipolarMatchOptions& options);

// Fundamental matrix F21 with x2^T F21 x1 = 0 for pixels x1 in view 1 and x2 in view 2.
Eigen::Matrix3d FundamentalFromPoses(const PinholeCamera& camera, const Rigid3d& cam1_from_world,
                                     const Rigid3d& cam2_from_world);

}  // namespace jvl::vision
