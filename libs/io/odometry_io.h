// The odometry artifact (schema "odometry" v1, schemas/odometry.schema.json): the trajectory
// group of the trajectory artifact plus per-frame diagnostics of the LiDAR odometry:
//
//   trajectory/{frames int64[N], poses double[N,7], timestamps double[N] (optional)}
//   diagnostics/{iterations int32[N], residual double[N], correspondences int32[N],
//                time_ms double[N], degenerate uint8[N], points_after_filter int64[N],
//                status int32[N], non_finite_points int64[N], min_eigenvalue double[N]}
//
// ReadTrajectory(path) reads the trajectory of this artifact like any other.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "geometry/trajectory.h"
#include "io/artifact.h"

namespace jvl::io {

inline constexpr const char* kOdometrySchema = "odometry";
inline constexpr int kOdometrySchemaVersion = 1;

// One entry per trajectory frame. status: 0 ok, 1 first frame, 2 degenerate (motion model
// along unobservable directions), 3 motion model only (too few points or correspondences).
struct OdometryDiagnostics {
  std::vector<int32_t> iterations;
  std::vector<double> residual;
  std::vector<int32_t> correspondences;
  std::vector<double> time_ms;
  std::vector<uint8_t> degenerate;
  std::vector<int64_t> points_after_filter;
  std::vector<int32_t> status;
  std::vector<int64_t> non_finite_points;
  std::vector<double> min_eigenvalue;
  size_t size() const { return iterations.size(); }
};

struct OdometryArtifact {
  Trajectory trajectory;
  OdometryDiagnostics diagnostics;
};

void WriteOdometryArtifact(const std::string& path, const OdometryArtifact& artifact,
                           const Provenance& provenance);
OdometryArtifact ReadOdometryArtifact(const std::string& path);

// How well each trajectory frame's registration was conditioned (diagnostics/min_eigenvalue; 0
// where the frame was not registered: the first frame and motion-model frames), the per-frame
// input of the global optimisation's odometry term. Empty if `path` is another kind of
// trajectory file (a KITTI or TUM text file, another artifact).
std::vector<double> ReadOdometryConditioning(const std::string& path);

}  // namespace jvl::io
