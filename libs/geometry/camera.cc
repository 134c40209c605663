#include "geometry/camera.h"

#include <cmath>

#include "core/check.h"

namespace jvl {

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

void PinholeCamera::Check() const {
  JVL_CHECK(std::isfinite(fx) && std::isfinite(fy) && fx > 0 && fy > 0,
            "camera focal lengths must be positive and finite (fx=" << fx << ", fy=" << fy << ")");
  JVL_CHECK(std::isfinite(cx) && std::isfinite(cy), "camera principal point is not finite");
}

}  // namespace jvl
