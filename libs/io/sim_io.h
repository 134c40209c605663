// Files of a synthetic sequence beyond the KITTI layout (which is written with io/kitti.h and
// io/trajectory_io.h): sequences/NN/sim/gt_vps.csv, gt_vps.json (schema "sim_vps" v1) and
// scene.json (schema "sim_scene" v1).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/camera.h"
#include "geometry/point_cloud.h"
#include "geometry/trajectory.h"
#include "io/artifact.h"

namespace jvl::io {

// Paths of a KITTI odometry layout rooted at `root` for sequence `sequence` ("00").
struct KittiLayout {
  std::string root, sequence;
  std::string SequenceDir() const;
  std::string ScanPath(int64_t frame) const;   // velodyne/000000.bin
  std::string ImagePath(int64_t frame) const;  // image_0/000000.png
  std::string PosesPath() const;               // root/poses/NN.txt
  std::string SimDir() const;                  // sequences/NN/sim
};

// calib.txt, times.txt and poses/NN.txt (12-column KITTI, world_from_cam0).
void WriteKittiSequenceMetadata(const KittiLayout& layout, const Calibration& calib,
                                const Trajectory& ground_truth);

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
