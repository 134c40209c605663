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

}  // namespace jvl
