// KITTI-360 drives (Liao, Xie, Geiger, TPAMI 2022; layout of its devkit, kitti360Scripts):
//
//   ROOT/calibration/perspective.txt          P_rect_00, R_rect_00, S_rect_00 (and _01)
//   ROOT/calibration/calib_cam_to_velo.txt    3 x 4: unrectified image_00 camera -> Velodyne
//   ROOT/calibration/calib_cam_to_pose.txt    image_00: 3 x 4, unrectified camera -> IMU/GPS pose
//   ROOT/data_3d_raw/DRIVE/velodyne_points/data/NNNNNNNNNN.bin (+ timestamps.txt)
//   ROOT/data_2d_raw/DRIVE/image_0{0,1}/data_rect/NNNNNNNNNN.png (+ timestamps.txt)
//   ROOT/data_poses/DRIVE/cam0_to_world.txt   frame + 4 x 4: rectified image_00 camera -> world
//   ROOT/data_poses/DRIVE/poses.txt           frame + 3 x 4: IMU/GPS pose -> world
//
// The dataset folder is any of ROOT/data_3d_raw/DRIVE, ROOT/data_2d_raw/DRIVE or
// ROOT/data_poses/DRIVE. Poses are world_from_cam0 of the rectified camera 0 (as for KITTI),
// cam0_from_velo = R_rect_00 * inverse(cam_to_velo). The ground truth comes from cam0_to_world.txt,
// or else from poses.txt * cam_to_pose(image_00) * inverse(R_rect_00) (the devkit's
// CameraPerspective), expressed relative to the drive's first posed frame; frames without a pose
// (the car standing still) are absent from it.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/strings.h"
#include "geometry/rigid3.h"
#include "io/dataset.h"

namespace jvl::io {

// ROOT and DRIVE of a KITTI-360 dataset folder, or nullopt if `dir` is not one (its parent is
// not data_3d_raw, data_2d_raw or data_poses, or ROOT/calibration/perspective.txt is missing).
struct Kitti360Location {
  std::string root;
  std::string drive;
};
std::optional<Kitti360Location> LocateKitti360(const std::string& dir);

// The lines "frame m00 ... m23" (12 numbers, poses.txt) or "frame m00 ... m33" (16 numbers,
// cam0_to_world.txt) of a KITTI-360 pose file, by frame. Throws naming the file and line.
std::map<int64_t, Rigid3d> ReadKitti360Poses(const std::string& path);

std::unique_ptr<Dataset> OpenKitti360Dataset(const std::string& dir, const FrameRange& range);

}  // namespace jvl::io
