// Two-view triangulation with known poses and the checks ORB-SLAM2 applies before a new map
// point is accepted (Mur-Artal & Tardos 2017; LocalMapping::CreateNewMapPoints): enough parallax,
// positive depth in both views, reprojection error within the chi-square bound of the keypoint's
// level, and a distance ratio consistent with the octave ratio.
#pragma once

#include <Eigen/Core>
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

}  // namespace jvl::vision
