#include "geometry/rigid3.h"

#include <Eigen/SVD>
#include <cmath>
#include <limits>

namespace jvl {

Rigid3d::Rigid3d(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation)
    : rotation_(Eigen::Quaterniond(rotation).normalized()), translation_(translation) {}

Rigid3d Rigid3d::FromMatrix(const Eigen::Matrix<double, 3, 4>& m) {
  // Project onto SO(3): text files carry ~1e-9 non-orthogonality.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(m.leftCols<3>(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) *= -1;
    r = u * svd.matrixV().transpose();
  }
  return Rigid3d(r, m.col(3));
}

double Rigid3d::RotationDeviation(const Eigen::Matrix3d& m) {
  if (!m.allFinite() || !(m.determinant() > 0)) return std::numeric_limits<double>::infinity();
  return (m.transpose() * m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
}

Rigid3d Rigid3d::FromArray(const double* a) {
  return Rigid3d(Eigen::Quaterniond(a[3], a[0], a[1], a[2]), Eigen::Vector3d(a[4], a[5], a[6]));
}

Eigen::Matrix<double, 3, 4> Rigid3d::Matrix3x4() const {
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = RotationMatrix();
  m.col(3) = translation_;
  return m;
}

Eigen::Matrix4d Rigid3d::Matrix4() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topRows<3>() = Matrix3x4();
  return m;
}

std::array<double, 7> Rigid3d::ToArray() const {
  return {rotation_.x(), rotation_.y(),    rotation_.z(),    rotation_.w(),
          translation_.x(), translation_.y(), translation_.z()};
}

Rigid3d Rigid3d::Inverse() const {
  const Eigen::Quaterniond inv = rotation_.conjugate();
  return Rigid3d(inv, -(inv * translation_));
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Eigen::Quaterniond ExpSO3(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  const double half = 0.5 * theta;
  double k;  // sin(theta/2)/theta
  if (theta < 1e-8) {
    k = 0.5 - theta * theta / 48.0;
  } else {
    k = std::sin(half) / theta;
  }
  return Eigen::Quaterniond(std::cos(half), k * omega.x(), k * omega.y(), k * omega.z())
      .normalized();
}

Eigen::Vector3d LogSO3(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0) q.coeffs() *= -1;  // Shortest rotation.
  const Eigen::Vector3d v = q.vec();
  const double s = v.norm();
  if (s < 1e-10) return 2.0 * v / q.w();  // theta ~ 2 s / w
  const double theta = 2.0 * std::atan2(s, q.w());
  return theta / s * v;
}

double RotationAngle(const Eigen::Quaterniond& q) { return LogSO3(q).norm(); }

namespace {

// Left Jacobian of SO(3) and its inverse.
Eigen::Matrix3d LeftJacobian(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  const Eigen::Matrix3d w = Skew(omega);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * w + w * w / 6.0;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() + (1 - std::cos(theta)) / t2 * w +
         (theta - std::sin(theta)) / (t2 * theta) * w * w;
}

Eigen::Matrix3d LeftJacobianInverse(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  const Eigen::Matrix3d w = Skew(omega);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * w + w * w / 12.0;
  const double t2 = theta * theta;
  const double coeff = 1.0 / t2 - (1 + std::cos(theta)) / (2 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() - 0.5 * w + coeff * w * w;
}

}  // namespace

Rigid3d ExpSE3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d omega = xi.tail<3>();
  return Rigid3d(ExpSO3(omega), LeftJacobian(omega) * rho);
}

Vector6d LogSE3(const Rigid3d& t) {
  const Eigen::Vector3d omega = LogSO3(t.rotation());
  Vector6d xi;
  xi.head<3>() = LeftJacobianInverse(omega) * t.translation();
  xi.tail<3>() = omega;
  return xi;
}

Rigid3d Interpolate(const Rigid3d& a, const Rigid3d& b, double s) {
  return a * ExpSE3(s * LogSE3(a.Inverse() * b));
}

Rigid3d InterpolateDecoupled(const Rigid3d& a, const Rigid3d& b, double s) {
  return Rigid3d(a.rotation().slerp(s, b.rotation()),
                 (1 - s) * a.translation() + s * b.translation());
}

}  // namespace jvl
