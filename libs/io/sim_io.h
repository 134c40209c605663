// Files of a synthetic sequence beyond the KITTI layout (which is written with io/kitti.h and
// io/trajectory_io.h): sequences/NN/sim/gt_vps.csv, gt_vps.json (schema "sim_vps" v1) and
// scene.json (schema "sim_scene" v1).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/camera.h"
#include "geometry/point_cloud.h"
#include "geometry/trajectory.h"
#include "io/artifact.h"

namespace jvl::io {

// The dataset layouts a simulated sequence can be written in (sim_sequence --layout).
enum class SimLayout {
  kKitti,     // ROOT/sequences/NN/{calib.txt, times.txt, velodyne/, image_0/}, ROOT/poses/NN.txt
  kKitti360,  // ROOT/calibration/, ROOT/data_3d_raw/DRIVE, data_2d_raw/DRIVE, data_poses/DRIVE
  kOxford,    // ROOT/sim-oxford-NN/{stereo/centre, velodyne_left, *.timestamps, gps/ins.csv},
              // ROOT/{extrinsics, models}
};
SimLayout ParseSimLayout(const std::string& name);  // kitti | kitti360 | oxford

// Paths of a simulated sequence `sequence` ("00") in `layout` rooted at `root`. KITTI-360 names
// the drive sim_drive_00NN_sync (the sequence as a four-digit drive number), Oxford the
// traversal sim-oxford-NN; Oxford's file names are the frames' times in µs (kOxfordSimEpochUs +
// `times`, which must then hold every frame's timestamp).
inline constexpr int64_t kOxfordSimEpochUs = 1547131008000000;  // 2019-01-10 14:36:48 UTC
struct SequenceLayout {
  SequenceLayout(std::string root_dir, std::string sequence_name,
                 SimLayout kind = SimLayout::kKitti)
      : root(std::move(root_dir)), sequence(std::move(sequence_name)), layout(kind) {}
  std::string root, sequence;
  SimLayout layout = SimLayout::kKitti;
  std::vector<double> times;                  // frame timestamps (s); Oxford only
  int64_t OxfordTime(int64_t frame) const;    // µs since 1970
  std::string Drive() const;                  // KITTI-360 drive / Oxford traversal folder name
  std::string SequenceDir() const;            // what the tools' --dataset takes
  std::string ScanPath(int64_t frame) const;  // velodyne/000000.bin, .../data/0000000000.bin
  // image_<camera>/000000.png, .../data_rect/0000000000.png (KITTI-360 and Oxford: camera 0).
  std::string ImagePath(int64_t frame, int camera = 0) const;
  std::string PosesPath() const;  // ROOT/poses/NN.txt, data_poses/DRIVE/cam0_to_world.txt
  std::string SimDir() const;     // SequenceDir()/sim
};

// The calibration, the timestamps and the ground truth (world_from_cam0) of the layout:
// KITTI: calib.txt, times.txt and poses/NN.txt (12 columns). KITTI-360: perspective.txt
// (P_rect_00/01, R_rect_00 = identity, S_rect_00 = the image size), calib_cam_to_velo.txt,
// calib_cam_to_pose.txt (the pose frame is the Velodyne's), timestamps.txt of the Velodyne and of
// camera 0 (from 2013-01-01 00:00:00), cam0_to_world.txt and poses.txt.
// Oxford: the SDK's files for the simulated rig in ROOT (models/stereo_narrow_left.txt with
// G_camera_image, an identity undistortion table, extrinsics/ with the vehicle frame at camera
// 0 and the INS there), stereo.timestamps and velodyne_left.timestamps (the same times: the
// simulator's camera and LiDAR are synchronous), gps/ins.csv at the frame times.
void WriteSequenceMetadata(const SequenceLayout& layout, const Calibration& calib,
                           const Trajectory& ground_truth);
// A scan in the layout's format (Oxford: planar float32, intensities 0-255).
void WriteSequenceScan(const SequenceLayout& layout, int64_t frame, const PointCloud& cloud);

// One ground-truth vanishing point (see sim/ground_truth.h).
struct GtVpRow {
  int64_t frame = 0;
  std::string kind;  // road | building_along | building_across | vertical
  int group = -1;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // Unit, camera frame, z >= 0.
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();         // NaN when at infinity.
  bool in_image = false;
  int buildings = 0;
};

// CSV with header "frame,kind,group,dx,dy,dz,u,v,in_image,buildings" (fixed formatting).
std::string FormatGtVpsCsv(const std::vector<GtVpRow>& rows);
void WriteGtVpsCsv(const std::string& path, const std::vector<GtVpRow>& rows);
std::vector<GtVpRow> ReadGtVpsCsv(const std::string& path);
// JSON artifact "sim_vps" v1: {camera: [fx fy cx cy w h], frames: [...], vps: [{...}]}.
void WriteGtVpsJson(const std::string& path, const PinholeCamera& camera,
                    const std::vector<int64_t>& frames, const std::vector<GtVpRow>& rows,
                    const Provenance& provenance);
// JSON artifact "sim_scene" v1 with the given body (sim::DescribeScene).
void WriteSceneJson(const std::string& path, const nlohmann::json& scene,
                    const Provenance& provenance);

}  // namespace jvl::io
