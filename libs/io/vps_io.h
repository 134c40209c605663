// The "vps" artifact (schema vps v1, schemas/vps.schema.json) written by vp_detect, and its CSV
// view (one row per VP) for people and scripts.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/camera.h"
#include "io/artifact.h"

namespace jvl::io {

constexpr char kVpsSchema[] = "vps";
constexpr int kVpsSchemaVersion = 1;

// One VP of one frame, as stored (plain values, independent of the vision library).
struct VpRecord {
  int64_t frame = 0;
  int32_t index = 0;                                     // 0..2 within its frame.
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();          // NaN when at infinity.
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // Unit, camera frame, z >= 0.
  int32_t inliers = 0;
  double residual_deg = 0;
  double score = 0;
  bool is_forward = false;
};

struct VpsData {
  std::vector<int64_t> frames;  // Every processed frame, also those without VPs.
  PinholeCamera camera;
  CameraChoice camera_choice;  // camera_index / camera_offset (camera 0 when absent)
  std::vector<VpRecord> vps;   // Grouped by frame in the order of `frames`.
};

// Writes the datasets into an open writer (schema "vps" v1).
void WriteVps(H5Writer& writer, const VpsData& data);
void WriteVpsArtifact(const std::string& path, const VpsData& data, const Provenance& provenance);
// Reads and checks the layout (shapes agree, frames of VPs are among `frames`).
VpsData ReadVpsArtifact(const std::string& path);

// CSV: header "frame,vp_index,u,v,dx,dy,dz,inliers,residual_deg,score,is_forward"; u, v are
// "nan" at infinity. Numbers use the shortest round-trip text.
std::string FormatVpsCsv(const VpsData& data);
void WriteVpsCsv(const std::string& path, const VpsData& data);

}  // namespace jvl::io
