// Two-view triangulation with known poses and the checks ORB-SLAM2 applies before a new map
// point is accepted (Mur-Artal & Tardos 2017; LocalMapping::CreateNewMapPoints): enough parallax,
// positive depth in both views, reprojection error within the chi-square bound of the keypoint's
// level, and a distance ratio consistent with the octave ratio.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"

namespace jvl::vision {

// Linear (DLT) triangulation from two views given cam_from_world and the normalised image rays
// (K^-1 [u v 1]). Solves A X = 0 with rows x P3 - P1, y P3 - P2 of each view by SVD
// (Hartley & Zisserman, Sec. 12.2). nullopt if the solution is at infinity.
std::optional<Eigen::Vector3d> TriangulateDlt(const Rigid3d& cam1_from_world,
                                              const Rigid3d& cam2_from_world,
                                              const Eigen::Vector2d& xn1,
                                              const Eigen::Vector2d& xn2);

// Midpoint of the shortest segment between the two viewing rays. nullopt for parallel rays.
std::optional<Eigen::Vector3d> TriangulateMidpoint(const Rigid3d& cam1_from_world,
                                                   const Rigid3d& cam2_from_world,
                                                   const Eigen::Vector2d& xn1,
                                                   const Eigen::Vector2d& xn2);

struct TriangulationOptions {
  double max_cos_parallax = 0.9998;      // Rays must differ by more than ~1.15 deg (ORB-SLAM2).
  double max_reprojection_chi2 = 5.991;  // chi2(2 dof, 95%) times the level variance.
  double scale_consistency = 1.5;        // Allowed factor between distance and octave ratios.
  void Check() const;
};

// One view of a point to be triangulated or checked.
struct PointView {
  Rigid3d cam_from_world;
  Eigen::Vector2d uv;
  double level_scale = 1.0;  // scale_factor^octave of the keypoint: sigma = level_scale px.
};

enum class TriangulationStatus {
  kOk,
  kLowParallax,
  kNoSolution,
  kBehindCamera,
  kReprojection,
  kScaleInconsistent
};
const char* ToString(TriangulationStatus status);

struct TriangulationResult {
  TriangulationStatus status = TriangulationStatus::kNoSolution;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // World frame (valid if kOk).
  double cos_parallax = 1.0;
};

// Triangulates (DLT) and applies all the checks.
TriangulationResult TriangulateTwoViews(const PinholeCamera& camera, const PointView& a,
                                        const PointView& b, const TriangulationOptions& options);

// Squared reprojection error in pixels, or +inf if the point is not in front of the camera.
double SquaredReprojectionError(const PinholeCamera& camera, const Rigid3d& cam_from_world,
                                const Eigen::Vector3d& point_world, const Eigen::Vector2d& uv);

// Structure-only refinement with the poses held fixed: Gauss-Newton on the sum of Huber-weighted
// reprojection errors (each view weighted by 1/level_scale^2). Returns the refined point, or the
// input when the system is degenerate.
Eigen::Vector3d RefinePoint(const PinholeCamera& camera, const std::vector<PointView>& views,
                            const Eigen::Vector3d& initial, int iterations = 5,
                            double huber_px = 2.0);

// One 3D-2D correspondence of a motion-only pose estimate.
struct PointObservation {
  Eigen::Vector3d point_world;
  Eigen::Vector2d uv;
  double level_scale = 1.0;  // sigma = level_scale px.
};

struct PoseRefinementOptions {
  int rounds = 4;                 // Outlier classification rounds (ORB-SLAM2's PoseOptimization).
  int iterations = 10;            // Gauss-Newton iterations per round.
  double chi2 = 5.991;            // Inlier bound on the squared error x 1 / level variance.
  double huber = 2.447746830680;  // sqrt(chi2(2, 0.95)): Huber threshold of the whitened error.
  // > 0: a Gaussian prior (sigma in m per axis) ties the camera centre to RefinePose's
  // `center_prior` (a monocular estimate fixes the scale along the motion poorly).
  double center_sigma = 0.0;
  void Check() const;
};

struct PoseRefinement {
  Rigid3d cam_from_world;
  std::vector<uint8_t> inlier;  // Per observation, at the final pose.
  int inliers = 0;
  bool ok = false;  // At least 6 inliers and a well-conditioned system in the last round.
};

// Motion-only refinement of a camera pose from 3D-2D matches with the points held fixed:
// Gauss-Newton on the Huber-weighted, level-whitened reprojection errors, in rounds; after each
// round an observation beyond chi2 is left out of the next one (and may return when the pose
// moves), as in ORB-SLAM2's PoseOptimization (Mur-Artal and Tardos 2017).
PoseRefinement RefinePose(const PinholeCamera& camera,
                          const std::vector<PointObservation>& observations,
                          const Rigid3d& initial_cam_from_world,
                          const PoseRefinementOptions& options = {},
                          const Eigen::Vector3d& center_prior = Eigen::Vector3d::Zero());

}  // namespace jvl::vision
