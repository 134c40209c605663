#include "optim/analytic_costs.h"

#include <Eigen/Geometry>

#include "geometry/angles.h"
#include "optim/cost_functions.h"

namespace jvl::optim {
namespace {

Eigen::Matrix3d SkewOf(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// d/d[u w] of v + 2 sign*w (u x v) + 2 u x (u x v); sign = +1 for R(q) v, -1 for R(q)^T v
// (conjugation flips u, and u x (u x v) is even in u).
Eigen::Matrix<double, 3, 4> RotateJacobianSigned(const double* q, const Eigen::Vector3d& v,
                                                 double sign) {
  const Eigen::Vector3d u(q[0], q[1], q[2]);
  const double w = q[3];
  Eigen::Matrix<double, 3, 4> j;
  j.leftCols<3>() =
      -2.0 * sign * w * SkewOf(v) +
      2.0 * (u.dot(v) * Eigen::Matrix3d::Identity() + u * v.transpose() - 2.0 * v * u.transpose());
  j.col(3) = 2.0 * sign * u.cross(v);
  return j;
}

}  // namespace

Eigen::Matrix<double, 3, 4> RotateJacobian(const double* q_xyzw, const Eigen::Vector3d& v) {
  return RotateJacobianSigned(q_xyzw, v, 1.0);
}

Eigen::Matrix<double, 3, 4> InverseRotateJacobian(const double* q_xyzw, const Eigen::Vector3d& v) {
  return RotateJacobianSigned(q_xyzw, v, -1.0);
}

// x_c = R_wc^T (X - t_wc) + o, r = s (uv - pi(x_c)). dr/dx_c = -s [fx/z 0 -fx x/z^2; 0 fy/z
// -fy y/z^2]; dx_c/dq = d(R^T d)/dq with d = X - t_wc, dx_c/dt_wc = -R_wc^T, dx_c/dX = R_wc^T (the
// constant offset o of the observing camera does not enter the derivatives of x_c).
bool VisualReprojectionAnalyticCost::Evaluate(double const* const* parameters, double* residuals,
                                              double** jacobians) const {
  const double* pose = parameters[0];
  const Eigen::Map<const Eigen::Quaterniond> q_wc(pose);
  const Eigen::Map<const Eigen::Vector3d> t_wc(pose + 4);
  const Eigen::Map<const Eigen::Vector3d> x_w(parameters[1]);
  const Eigen::Vector3d d = x_w - t_wc;
  const Eigen::Vector3d x_c = q_wc.conjugate() * d + offset_;
  if (!(x_c.z() > VisualReprojectionCost::kMinDepth)) return false;
  const double inv_z = 1.0 / x_c.z();
  const double s = sqrt_information_;
  residuals[0] = s * (uv_.x() - (fx_ * x_c.x() * inv_z + cx_));
  residuals[1] = s * (uv_.y() - (fy_ * x_c.y() * inv_z + cy_));
  if (jacobians == nullptr || (jacobians[0] == nullptr && jacobians[1] == nullptr)) return true;
  const Eigen::Matrix<double, 2, 3> dr_dx = PixelResidualJacobian(fx_, fy_, s, x_c);
  const Eigen::Matrix<double, 2, 3> dr_dx_rt = dr_dx * q_wc.conjugate().toRotationMatrix();
  if (jacobians[0] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> j(jacobians[0]);
    j.leftCols<4>() = dr_dx * InverseRotateJacobian(pose, d);
    j.rightCols<3>() = -dr_dx_rt;
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> j(jacobians[1]);
    j = dr_dx_rt;
  }
  return true;
}

// r = s (n . R_wc^T (p_w - t_wc) - n . c_p_y) = s (g . (p_w - t_wc) - n . c_p_y), g = R_wc n,
// p_w = R_wn p_x + t_wn. Hence dr/dt_wn = s g^T, dr/dt_wc = -s g^T,
// dr/dq_n = s g^T d(R_wn p_x)/dq_n, dr/dq_c = s n^T d(R_wc^T w)/dq_c with w = p_w - t_wc.
bool PointToImlsAnalyticCost::Evaluate(double const* const* parameters, double* residuals,
                                       double** jacobians) const {
  const double* pose_n = parameters[0];
  const double* pose_c = parameters[1];
  const Eigen::Map<const Eigen::Quaterniond> q_wn(pose_n);
  const Eigen::Map<const Eigen::Vector3d> t_wn(pose_n + 4);
  const Eigen::Map<const Eigen::Quaterniond> q_wc(pose_c);
  const Eigen::Map<const Eigen::Vector3d> t_wc(pose_c + 4);
  const Eigen::Vector3d w = q_wn * p_x_ + t_wn - t_wc;
  const Eigen::Vector3d g = q_wc * c_normal_;
  const double s = sqrt_information_;
  residuals[0] = s * (g.dot(w) - c_normal_.dot(c_p_y_));
  if (jacobians == nullptr) return true;
  if (jacobians[0] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 1, 7>> j(jacobians[0]);
    j.head<4>() = s * g.transpose() * RotateJacobian(pose_n, p_x_);
    j.tail<3>() = s * g.transpose();
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 1, 7>> j(jacobians[1]);
    j.head<4>() = s * c_normal_.transpose() * InverseRotateJacobian(pose_c, w);
    j.tail<3>() = -s * g.transpose();
  }
  return true;
}

// r = s (v - pi(d)), d = +-R_wn^T d_w (flipped to z >= 0, z clamped at min_z as in the autodiff
// functor). dr/dd = -s [fx/z 0 -fx x/z^2; 0 fy/z -fy y/z^2] (third column 0 when clamped);
// dr/dq = dr/dd * sign * d(R^T d_w)/dq; the translation columns are exactly zero.
namespace {

// Shared by the fixed and the free form: residual and Jacobians w.r.t. the pose quaternion
// (2 x 4) and the world direction (2 x 3) of r = s (v - pi(+-R_wn^T d_w)).
bool EvaluateDirection(const PinholeCamera& camera, const Eigen::Vector2d& vp,
                       const Eigen::Vector2d& s, double min_z, const double* pose,
                       const Eigen::Vector3d& d_w, double* residuals, double* jac_pose,
                       double* jac_direction) {
  const Eigen::Map<const Eigen::Quaterniond> q_wc(pose);
  Eigen::Vector3d d = q_wc.conjugate() * d_w;
  const double sign = d.z() < 0 ? -1.0 : 1.0;
  d *= sign;
  const bool clamped = d.z() < min_z;
  if (clamped) d.z() = min_z;
  const double inv_z = 1.0 / d.z();
  residuals[0] = s.x() * (vp.x() - (camera.fx * d.x() * inv_z + camera.cx));
  residuals[1] = s.y() * (vp.y() - (camera.fy * d.y() * inv_z + camera.cy));
  if (jac_pose == nullptr && jac_direction == nullptr) return true;
  Eigen::Matrix<double, 2, 3> dr_dd = PixelResidualJacobian(camera.fx, camera.fy, 1.0, d);
  dr_dd.row(0) *= s.x();
  dr_dd.row(1) *= s.y();
  if (clamped) dr_dd.col(2).setZero();
  if (jac_pose != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> j(jac_pose);
    j.leftCols<4>() = sign * dr_dd * InverseRotateJacobian(pose, d_w);
    j.rightCols<3>().setZero();
  }
  if (jac_direction != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> j(jac_direction);
    j = sign * dr_dd * q_wc.conjugate().toRotationMatrix();
  }
  return true;
}

}  // namespace

bool DirectionProjectionAnalyticCost::Evaluate(double const* const* parameters, double* residuals,
                                               double** jacobians) const {
  return EvaluateDirection(camera_, vp_, sqrt_information_, min_z_, parameters[0], direction_world_,
                           residuals, jacobians != nullptr ? jacobians[0] : nullptr, nullptr);
}

// The direction block is kept unit by its sphere manifold; it is used as stored.
bool DirectionProjectionFreeCost::Evaluate(double const* const* parameters, double* residuals,
                                           double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> d_w(parameters[1]);
  return EvaluateDirection(camera_, vp_, sqrt_information_, min_z_, parameters[0], d_w, residuals,
                           jacobians != nullptr ? jacobians[0] : nullptr,
                           jacobians != nullptr ? jacobians[1] : nullptr);
}

DirectionAngleFreeCost::DirectionAngleFreeCost(const Eigen::Vector3d& ray_cam,
                                               double sqrt_information)
    : ray_(ray_cam.normalized()), basis_(TangentBasis(ray_)), sqrt_information_(sqrt_information) {}

bool DirectionAngleFreeCost::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  const double* pose = parameters[0];
  const Eigen::Map<const Eigen::Quaterniond> q_wc(pose);
  const Eigen::Map<const Eigen::Vector3d> d_w(parameters[1]);
  const Eigen::Vector3d d = q_wc.conjugate() * d_w;
  const double s = (ray_.dot(d) < 0 ? -1.0 : 1.0) * sqrt_information_;
  const Eigen::Matrix<double, 2, 3> bt = s * basis_.transpose();
  Eigen::Map<Eigen::Vector2d> r(residuals);
  r = bt * d;
  if (jacobians == nullptr) return true;
  if (jacobians[0] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> j(jacobians[0]);
    j.leftCols<4>() = bt * InverseRotateJacobian(pose, d_w);
    j.rightCols<3>().setZero();
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> j(jacobians[1]);
    j = bt * q_wc.conjugate().toRotationMatrix();
  }
  return true;
}

}  // namespace jvl::optim
