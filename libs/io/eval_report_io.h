// Files of the evaluate stage: pose files read as raw matrices, sequence folders, reports.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/artifact.h"
#include "io/trajectory_io.h"

namespace jvl::io {

// Poses exactly as a file gives them. KITTI text keeps its 3x4 matrices untouched (the KITTI
// devkit evaluates them so, without re-orthonormalising the rotation); TUM text and HDF5
// artifacts are converted from their quaternions.
struct PoseMatrices {
  std::vector<int64_t> frames;
  std::vector<Eigen::Matrix4d> poses;  // world_from_cam
  std::vector<double> timestamps;      // Empty when the file has none.
};
PoseMatrices ReadPoseMatrices(const std::string& path,
                              TrajectoryFormat format = TrajectoryFormat::kAuto);
PoseMatrices ParsePoseMatricesKitti(std::istream& in, const std::string& name);

// Trajectory files (*.txt, *.h5) directly inside `dir`, sorted by name.
std::vector<std::string> ListTrajectoryFiles(const std::string& dir);

// The metrics report (schema "metrics", version 1; schemas/metrics.schema.json).
inline constexpr const char* kMetricsSchema = "metrics";
inline constexpr int kMetricsSchemaVersion = 1;
void WriteMetricsReport(const std::string& path, const nlohmann::json& body,
                        const Provenance& provenance);
nlohmann::json ReadMetricsReport(const std::string& path);

}  // namespace jvl::io
