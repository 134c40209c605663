// Sensor calibration of a KITTI-style rig: rectified projection matrices of the cameras and the
// LiDAR-to-cam0 extrinsic (KITTI's Tr = cam0_from_velo).
#pragma once

#include <Eigen/Core>
#include <array>

#include "geometry/camera.h"
#include "geometry/rigid3.h"

namespace jvl {

struct Calibration {
  std::array<Eigen::Matrix<double, 3, 4>, 4> P{};  // P0..P3 (rectified, cam0 frame).
  Rigid3d cam0_from_velo;                          // Tr.
  int image_width = 0, image_height = 0;           // 0 if unknown.

  // Intrinsics of camera i from P_i (K is the left 3x3 block).
  PinholeCamera Camera(int i = 0) const;
};

}  // namespace jvl
