#include "optim/imls_pair_cost.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>

#include "optim/analytic_costs.h"

namespace jvl::optim {

void ImlsPairAccumulator::Add(const Eigen::Vector3d& p_x, const Eigen::Vector3d& c_p_y,
                              const Eigen::Vector3d& c_normal) {
  Eigen::Matrix<double, 13, 1> a;
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) a[3 * j + k] = c_normal[j] * p_x[k];
  a.segment<3>(9) = c_normal;
  a[12] = -c_normal.dot(c_p_y);
  h_.selfadjointView<Eigen::Lower>().rankUpdate(a);
  ++count_;
}

void ImlsPairAccumulator::Merge(const ImlsPairAccumulator& other) {
  h_.triangularView<Eigen::Lower>() += other.h_;
  count_ += other.count_;
}

ImlsPairCost::ImlsPairCost(const ImlsPairAccumulator& pair, double sqrt_information) {
  // H = P^T L D L^T P (LDL^T with diagonal pivoting, fine for semi-definite H), hence
  // x^T H x = |D^1/2 L^T P x|^2. With fewer than 13 independent correspondences H is singular and
  // rounding leaves the pivots of its null space at about 1e-15 of the largest, of either sign;
  // pivots below 1e-12 of the largest are taken as zero and their rows left out.
  const Eigen::Matrix<double, 13, 13> h =
      sqrt_information * sqrt_information *
      Eigen::Matrix<double, 13, 13>(pair.information().selfadjointView<Eigen::Lower>());
  const Eigen::LDLT<Eigen::Matrix<double, 13, 13>> ldlt(h);
  Eigen::Matrix<double, 13, 13> lt_p = Eigen::Matrix<double, 13, 13>::Identity();
  lt_p = ldlt.transpositionsP() * lt_p;                          // P
  lt_p = ldlt.matrixL().transpose() * lt_p;                      // L^T P
  const double threshold = 1e-12 * ldlt.vectorD().cwiseAbs().maxCoeff();
  int rank = 0;
  for (int r = 0; r < 13; ++r) rank += ldlt.vectorD()[r] > threshold ? 1 : 0;
  sqrt_h_.resize(rank, 13);
  for (int r = 0, row = 0; r < 13; ++r) {
    const double d = ldlt.vectorD()[r];
    if (d > threshold) sqrt_h_.row(row++) = std::sqrt(d) * lt_p.row(r);
  }
  set_num_residuals(rank);
  mutable_parameter_block_sizes()->assign({7, 7});
}

Eigen::Matrix<double, 13, 1> ImlsPairCost::RelativePoseVector(const double* pose_n,
                                                              const double* pose_c) {
  const Eigen::Map<const Eigen::Quaterniond> q_wn(pose_n);
  const Eigen::Map<const Eigen::Vector3d> t_wn(pose_n + 4);
  const Eigen::Map<const Eigen::Quaterniond> q_wc(pose_c);
  const Eigen::Map<const Eigen::Vector3d> t_wc(pose_c + 4);
  const Eigen::Quaterniond q_cw = q_wc.conjugate();
  Eigen::Matrix<double, 13, 1> x;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d col = q_cw * (q_wn * Eigen::Vector3d::Unit(k));  // R_cn e_k
    for (int j = 0; j < 3; ++j) x[3 * j + k] = col[j];
  }
  x.segment<3>(9) = q_cw * (t_wn - t_wc);
  x[12] = 1.0;
  return x;
}

// dx/dpose_n: rows 3j+k of column k of R_cn = R_wc^T (R_wn e_k) -> R_wc^T d(R_wn e_k)/dq_n;
// t_cn rows: R_wc^T for t_wn. dx/dpose_c: d(R_wc^T v)/dq_c with v = R_wn e_k resp. t_wn - t_wc;
// -R_wc^T for t_wc. The constant row 12 has zero derivative.
bool ImlsPairCost::Evaluate(double const* const* parameters, double* residuals,
                            double** jacobians) const {
  const double* pose_n = parameters[0];
  const double* pose_c = parameters[1];
  const Eigen::Matrix<double, 13, 1> x = RelativePoseVector(pose_n, pose_c);
  const int rank = static_cast<int>(sqrt_h_.rows());
  Eigen::Map<Eigen::VectorXd>(residuals, rank) = sqrt_h_ * x;
  if (jacobians == nullptr || (jacobians[0] == nullptr && jacobians[1] == nullptr)) return true;

  const Eigen::Map<const Eigen::Quaterniond> q_wn(pose_n);
  const Eigen::Map<const Eigen::Vector3d> t_wn(pose_n + 4);
  const Eigen::Map<const Eigen::Quaterniond> q_wc(pose_c);
  const Eigen::Map<const Eigen::Vector3d> t_wc(pose_c + 4);
  const Eigen::Quaterniond q_cw = q_wc.conjugate();
  Eigen::Matrix3d r_cw;
  for (int k = 0; k < 3; ++k) r_cw.col(k) = q_cw * Eigen::Vector3d::Unit(k);
  using Jac = Eigen::Matrix<double, 13, 7>;
  using OutJac = Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>;
  if (jacobians[0] != nullptr) {
    Jac dx = Jac::Zero();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Matrix<double, 3, 4> d = r_cw * RotateJacobian(pose_n, Eigen::Vector3d::Unit(k));
      for (int j = 0; j < 3; ++j) dx.block<1, 4>(3 * j + k, 0) = d.row(j);
    }
    dx.block<3, 3>(9, 4) = r_cw;
    Eigen::Map<OutJac>(jacobians[0], rank, 7) = sqrt_h_ * dx;
  }
  if (jacobians[1] != nullptr) {
    Jac dx = Jac::Zero();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Matrix<double, 3, 4> d =
          InverseRotateJacobian(pose_c, q_wn * Eigen::Vector3d::Unit(k));
      for (int j = 0; j < 3; ++j) dx.block<1, 4>(3 * j + k, 0) = d.row(j);
    }
    dx.block<3, 4>(9, 0) = InverseRotateJacobian(pose_c, t_wn - t_wc);
    dx.block<3, 3>(9, 4) = -r_cw;
    Eigen::Map<OutJac>(jacobians[1], rank, 7) = sqrt_h_ * dx;
  }
  return true;
}

}  // namespace jvl::optim
