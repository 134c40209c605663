// Sensor calibration of a KITTI-style rig: rectified projection matrices of the cameras and the
// LiDAR-to-cam0 extrinsic (KITTI's Tr = cam0_from_velo).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

#include "geometry/camera.h"
#include "geometry/rigid3.h"

namespace jvl {

struct Calibration {
  // P0..P3 (rectified, cam0 frame); all zero until set (Eigen leaves a matrix uninitialised).
  std::array<Eigen::Matrix<double, 3, 4>, 4> P = ZeroProjections();
  Rigid3d cam0_from_velo;                 // Tr.
  int image_width = 0, image_height = 0;  // 0 if unknown.

  // Intrinsics of camera i from P_i (K is the left 3x3 block).
  PinholeCamera Camera(int i = 0) const;
  // Camera i's offset from camera 0: the translation t_i of x_i = x_0 + t_i (a point in the
  // rectified camera-0 frame to camera i's frame), t_i = K_i^-1 P_i(:, 3). The rectified cameras
  // share camera 0's orientation (P_i = K_i [I | t_i]); zero for camera 0.
  Eigen::Vector3d CameraOffset(int i) const;
  // Throws a one-line error naming `source` unless camera i has a projection (a positive focal
  // length and principal point: P_i is not all zero).
  void CheckCamera(int i, const std::string& source) const;

  static std::array<Eigen::Matrix<double, 3, 4>, 4> ZeroProjections() {
    std::array<Eigen::Matrix<double, 3, 4>, 4> p;
    for (auto& m : p) m.setZero();
    return p;
  }
};

// The camera an image stage used: its index and its offset from camera 0 (x_camera = x_cam0 +
// offset, Calibration::CameraOffset). Poses in every artifact stay world_from_cam0; the visual
// terms see the points through this camera.
struct CameraChoice {
  int index = 0;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  static CameraChoice Of(const Calibration& calibration, int index) {
    return {index, calibration.CameraOffset(index)};
  }
  Rigid3d camera_from_cam0() const { return {Eigen::Quaterniond::Identity(), offset}; }
};

}  // namespace jvl
