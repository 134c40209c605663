// A complete synthetic sequence: route, scene, drive and sensor rig, and the per-frame sensor
// data (LiDAR scan, camera image) plus ground truth (poses, vanishing points).
//
// Frames: the world frame of the poses is cam0 of frame 0 (as KITTI's poses/NN.txt); the scene
// itself is built in a map frame (x east, y north, z up), related by World::map_from_world.
#pragma once

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/point_cloud.h"
#include "geometry/trajectory.h"
#include "sim/ground_truth.h"
#include "sim/lidar.h"
#include "sim/raycaster.h"
#include "sim/render.h"
#include "sim/road.h"
#include "sim/scene.h"

namespace jvl::sim {

// KITTI odometry calibration of sequence 04 (calib.txt: P0..P3 and Tr), image 1226 x 370.
Calibration KittiCalibration();

struct SequenceOptions {
  Scenario scenario = Scenario::kUrban;
  uint64_t seed = 1;
  int64_t frames = 0;  // 0: drive the whole route.
  int laps = 1;        // Route repetitions (see ScenarioRoute), for long sequences.
  bool stop = false;   // Stop for a few seconds before the second corner.
  // The road and its world continue this far (m) straight beyond both ends of the drive (lead
  // pieces, WithLeads): real drives never see the end of the world. Default: the LiDAR's
  // maximum range. 0: the world ends where the drive does.
  double road_beyond = 120.0;
  double lidar_height = 1.73;  // Velodyne above the road (KITTI setup).
  Calibration calibration = KittiCalibration();
  // Calibration error: the calib.txt written holds the camera-LiDAR extrinsic (Tr) off the rig
  // the data were made with by a rotation of calib_error_deg about an axis and a translation of
  // calib_error_m along a direction, both drawn from the seed (0, 0: the true rig).
  double calib_error_deg = 0.0;
  double calib_error_m = 0.0;
  DriveOptions drive;
  SceneOptions scene;
  LidarOptions lidar;
  CameraOptions camera;
  bool render_images = true;
  // The cameras rendered (0..3, each at its offset from camera 0 in the calibration); 2 and 3
  // are written as colour images (three equal channels), as KITTI stores them.
  std::vector<int> cameras = {0};
  bool simulate_scans = true;
  void Check() const;
};

struct World {
  SequenceOptions options;
  Scene scene;
  std::unique_ptr<RayCaster> caster;
  Drive drive;
  Rigid3d map_from_world;         // Map frame from the pose world frame (cam0 of frame 0).
  Trajectory ground_truth;        // world_from_cam0 per frame, with timestamps.
  Trajectory MapFromCam() const;  // The same poses in the map frame.
  Rigid3d MapFromVeloAt(double t) const;
};

std::unique_ptr<World> BuildWorld(const SequenceOptions& options);

// The calibration written with the sequence: options.calibration with its cam0_from_velo moved
// by the calibration error (WrittenCalibrationError x cam0_from_velo).
Calibration WrittenCalibration(const SequenceOptions& options);
// The calibration error as written cam0 from true cam0 (identity without one).
Rigid3d WrittenCalibrationError(const SequenceOptions& options);

struct SimFrame {
  int64_t frame = 0;
  double time = 0;
  PointCloud scan;  // Velodyne frame; empty when scans are disabled.
  cv::Mat image;  // CV_8U of camera 0; empty when images are disabled or camera 0 is not rendered.
  std::vector<std::pair<int, cv::Mat>>
      other_images;  // The other rendered cameras (CV_8UC3 for 2, 3).
  std::vector<GtVanishingPoint> vps;
};

SimFrame SimulateFrame(const World& world, int64_t frame);

// Simulates every frame on `threads` threads; sink(frame) is called from the worker threads
// (each frame exactly once, in no particular order). Results depend only on the frame index.
void GenerateSequence(const World& world, int threads, const std::function<void(SimFrame&&)>& sink);

}  // namespace jvl::sim
