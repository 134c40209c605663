// Rigid transforms. Name them b_from_a: p_b = b_from_a * p_a, and c_from_a = c_from_b * b_from_a.
// Stored as a unit quaternion and a translation; the 7-vector layout [qx, qy, qz, qw, tx, ty, tz]
// is the artifact layout and maps directly onto Ceres' EigenQuaternionManifold.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

namespace jvl {

using Vector6d = Eigen::Matrix<double, 6, 1>;

class Rigid3d {
 public:
  Rigid3d() : rotation_(Eigen::Quaterniond::Identity()), translation_(Eigen::Vector3d::Zero()) {}
  Rigid3d(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
      : rotation_(rotation.normalized()), translation_(translation) {}
  Rigid3d(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation);
  // From a 3x4 or 4x4 matrix [R | t]; the rotation is projected onto SO(3).
  static Rigid3d FromMatrix(const Eigen::Matrix<double, 3, 4>& m);
  // Largest entry of |m^T m - I| for the 3x3 part of a matrix read from text (infinity when it is
  // not finite or det(m) <= 0): readers reject values far above KITTI's ~1e-7 before FromMatrix.
  static double RotationDeviation(const Eigen::Matrix3d& m);
  // [qx, qy, qz, qw, tx, ty, tz].
  static Rigid3d FromArray(const double* q_xyzw_t);

  const Eigen::Quaterniond& rotation() const { return rotation_; }
  const Eigen::Vector3d& translation() const { return translation_; }
  Eigen::Matrix3d RotationMatrix() const { return rotation_.toRotationMatrix(); }
  Eigen::Matrix<double, 3, 4> Matrix3x4() const;
  Eigen::Matrix4d Matrix4() const;
  std::array<double, 7> ToArray() const;

  Rigid3d Inverse() const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return rotation_ * p + translation_; }
  Rigid3d operator*(const Rigid3d& other) const {
    return Rigid3d(rotation_ * other.rotation_, rotation_ * other.translation_ + translation_);
  }

 private:
  Eigen::Quaterniond rotation_;
  Eigen::Vector3d translation_;
};

// SO(3) exponential / logarithm (axis-angle vector), stable near zero and near pi.
Eigen::Quaterniond ExpSO3(const Eigen::Vector3d& omega);
Eigen::Vector3d LogSO3(const Eigen::Quaterniond& q);
// Rotation angle of q in radians, in [0, pi].
double RotationAngle(const Eigen::Quaterniond& q);
Eigen::Matrix3d Skew(const Eigen::Vector3d& v);

// SE(3) exponential / logarithm with tangent [rho (translation part); omega (rotation part)].
Rigid3d ExpSE3(const Vector6d& xi);
Vector6d LogSE3(const Rigid3d& t);

// Geodesic interpolation on SE(3): a * Exp(s * Log(a^-1 b)), s in [0, 1].
Rigid3d Interpolate(const Rigid3d& a, const Rigid3d& b, double s);
// Slerp for rotation and linear for translation (what trajectories usually mean).
Rigid3d InterpolateDecoupled(const Rigid3d& a, const Rigid3d& b, double s);

}  // namespace jvl
