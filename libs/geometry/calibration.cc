#include "geometry/calibration.h"

#include "core/check.h"

namespace jvl {

PinholeCamera Calibration::Camera(int i) const {
  JVL_CHECK(i >= 0 && i < 4, "camera index " << i << " out of range 0..3");
  const auto& p = P[i];
  PinholeCamera cam{p(0, 0), p(1, 1), p(0, 2), p(1, 2), image_width, image_height};
  return cam;
}

Eigen::Vector3d Calibration::CameraOffset(int i) const {
  const PinholeCamera cam = Camera(i);
  JVL_CHECK(cam.fx > 0 && cam.fy > 0, "camera " << i << " has no projection (P" << i << " is "
                                                << "not set)");
  return cam.K().inverse() * P[i].col(3);
}

void Calibration::CheckCamera(int i, const std::string& source) const {
  JVL_CHECK(i >= 0 && i < 4, "--camera " << i << " is not a camera (0..3)");
  const PinholeCamera cam = Camera(i);
  JVL_CHECK(cam.fx > 0 && cam.fy > 0 && cam.cx > 0 && cam.cy > 0,
            source << " has no projection of camera " << i << " (P" << i << ")");
}

}  // namespace jvl
