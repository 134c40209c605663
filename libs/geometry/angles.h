// Angles between directions.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace jvl {

constexpr double kDegPerRad = 180.0 / M_PI;

// Angle between two (not necessarily unit) vectors in degrees, in [0, 180]; atan2 of the sine
// and cosine parts stays accurate for nearly parallel vectors, where acos of a dot does not.
inline double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kDegPerRad;
}

// An orthonormal basis (columns) of the plane normal to the unit vector `unit`: the first axis is
// unit x (x, or y when unit is near x), normalised; the second unit x first.
inline Eigen::Matrix<double, 3, 2> TangentBasis(const Eigen::Vector3d& unit) {
  const Eigen::Vector3d helper =
      std::abs(unit.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  Eigen::Matrix<double, 3, 2> basis;
  basis.col(0) = unit.cross(helper).normalized();
  basis.col(1) = unit.cross(basis.col(0));
  return basis;
}

}  // namespace jvl
