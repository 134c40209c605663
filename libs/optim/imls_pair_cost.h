// All point-to-IMLS residuals between one pair of keyframes (n, c) as one exact residual block.
//
// Each correspondence of the pair gives (analytic_costs.h, supplement Eq. 1)
//   r_i = s (n_i . (R_cn p_i + t_cn) - n_i . y_i),   R_cn = R_wc^T R_wn,  t_cn = R_wc^T (t_wn - t_wc),
// which is linear in the 13-vector x = [R_cn(0,0) R_cn(0,1) .. R_cn(2,2)  t_cn  1]:
//   r_i = a_i . x,   a_i = s [n_i p_i^T (row-major)  n_i  -n_i . y_i].
// Without a robust kernel the pair's cost is therefore sum_i r_i^2 = x^T H x with H = sum a_i a_i^T
// (13 x 13, positive semi-definite). With the pivoted factorisation H = P^T L D L^T P the block
// residual
//   r = D^1/2 L^T P x   (one row per non-zero pivot of D: at most 13)
// has |r|^2 = sum_i r_i^2 at every pose, and its Gauss-Newton matrix and gradient are those of
// the individual residuals (J^T J = X^T H X, X = dx/dpose), so Levenberg-Marquardt takes the same
// steps; only the number of residual blocks shrinks (millions of correspondences -> one block per
// keyframe pair). The same aggregation of point-to-plane terms into a constant matrix underlies
// the "point cluster" of BALM2 (Liu et al., IEEE T-RO 2023).
//
// A robust kernel on e_L (JointProblemOptions::imls_huber > 0) acts per correspondence and cannot
// be aggregated; the problem builder then keeps one block per correspondence.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <cstdint>

namespace jvl::optim {

// Sum of a_i a_i^T / s^2 over the correspondences of one keyframe pair (see above; the noise s
// enters when the cost is made, so sums can be kept and merged independently of it).
class ImlsPairAccumulator {
 public:
  void Add(const Eigen::Vector3d& p_x, const Eigen::Vector3d& c_p_y,
           const Eigen::Vector3d& c_normal);
  void Merge(const ImlsPairAccumulator& other);
  int64_t count() const { return count_; }
  // Lower triangle of H / s^2.
  const Eigen::Matrix<double, 13, 13>& information() const { return h_; }

 private:
  Eigen::Matrix<double, 13, 13> h_ = Eigen::Matrix<double, 13, 13>::Zero();
  int64_t count_ = 0;
};

class ImlsPairCost : public ceres::CostFunction {
 public:
  ImlsPairCost(const ImlsPairAccumulator& pair, double sqrt_information);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  int rank() const { return static_cast<int>(sqrt_h_.rows()); }  // 0: nothing to add

  // x of the header comment for the two pose blocks [qx qy qz qw tx ty tz] (world_from_cam).
  static Eigen::Matrix<double, 13, 1> RelativePoseVector(const double* pose_n,
                                                         const double* pose_c);

 private:
  Eigen::Matrix<double, Eigen::Dynamic, 13, Eigen::RowMajor> sqrt_h_;  // rank x 13
};

}  // namespace jvl::optim
