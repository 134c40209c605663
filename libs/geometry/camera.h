// Pinhole camera (no distortion: KITTI images are rectified). Eq. (1) of the paper.
#pragma once

#include <Eigen/Core>

namespace jvl {

struct PinholeCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;

  Eigen::Matrix3d K() const;
  // pi(X) = (fx X/Z + cx, fy Y/Z + cy). Caller checks Z > 0.
  Eigen::Vector2d Project(const Eigen::Vector3d& p_cam) const {
    return {fx * p_cam.x() / p_cam.z() + cx, fy * p_cam.y() / p_cam.z() + cy};
  }
  // Ray K^-1 [u v 1]^T (z = 1, not normalised).
  Eigen::Vector3d Unproject(const Eigen::Vector2d& uv) const {
    return {(uv.x() - cx) / fx, (uv.y() - cy) / fy, 1.0};
  }
  bool InImage(const Eigen::Vector2d& uv, double border = 0) const {
    return uv.x() >= border && uv.y() >= border && uv.x() < width - border &&
           uv.y() < height - border;
  }
  void Check() const;
};

}  // namespace jvl
