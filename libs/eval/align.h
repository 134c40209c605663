// Trajectory alignment: a similarity transform fitted by Umeyama on associated positions.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace jvl::eval {

enum class Alignment { kNone, kOrigin, kSE3, kSim3 };
Alignment ParseAlignment(const std::string& name);  // none|origin|se3|sim3
std::string ToString(Alignment alignment);

// gt_from_est as a similarity: p_gt = scale * rotation * p_est + translation.
struct Similarity {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;
  // Second over first singular value of the position cross-covariance (1 for a well spread
  // trajectory). Near 0 the positions lie on a line, and the rotation about that line, hence
  // the aligned rotation errors, are not determined by the positions.
  double conditioning = 1.0;
  bool IllConditioned() const { return conditioning < kMinConditioning; }
  static constexpr double kMinConditioning = 1e-3;

  // The pose moved by the similarity: its translation is scaled, then rotated and shifted; its
  // rotation block is rotated (the order kitti-odom-eval and evo use).
  Eigen::Matrix4d Apply(const Eigen::Matrix4d& pose) const;
};

// Least-squares similarity (with_scale) or rigid transform mapping src onto dst.
// Umeyama, "Least-squares estimation of transformation parameters between two point patterns",
// IEEE PAMI 13(4), 1991: means (eq. 34, 35), variance of src (eq. 36), covariance (eq. 38),
// S = diag(1, 1, -1) when det(U) det(V) < 0 (eq. 43), R = U S V^T (eq. 40),
// c = tr(D S) / sigma_src^2 (eq. 42), t = mu_dst - c R mu_src (eq. 41).
// Throws for fewer than 3 points or all source points equal.
Similarity Umeyama(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst,
                   bool with_scale);

}  // namespace jvl::eval
