// The "local" artifact (schema "local" v1, schemas/local.schema.json) written by local_map
// (paper Sec. 4.2) and read by global optimisation:
//
//   camera double[6] (fx fy cx cy width height)
//   keyframes/{frames, poses}        trajectory group: refined poses, same rows as visual.h5
//   imls/{n int32[L], c int32[L], p_x double[L,3], p_y double[L,3], normal double[L,3]}
//                                    the saved correspondence set L (keyframe rows; p_x in n's
//                                    cam frame, p_y and normal in c's cam frame)
//   mappoints/position double[M,3]   refined, same rows as visual.h5 mappoints
//   scans/{offset int64[K+1], points float[S,3], normals float[S,3]}
//                                    per keyframe the preprocessed, downsampled scan (own frame)
//   stats/{frame int64[K], visual_residuals int32[K], imls_residuals int32[K],
//          cost_before double[K], cost_after double[K], time_ms double[K]}
//   prior/{frames, poses, timestamps}  the full prior trajectory
//   attribute "summary" (JSON)
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/camera.h"
#include "geometry/trajectory.h"
#include "io/artifact.h"

namespace jvl::io {

inline constexpr const char* kLocalSchema = "local";
inline constexpr int kLocalSchemaVersion = 1;

// What ReadLocalMap reads. kWithoutCorrespondences leaves out the saved IMLS set and the map
// points (imls_* and mappoint_position stay empty): most of the file on long sequences, and all
// a map export does not need. kWithoutScans leaves out scans/points and scans/normals (scan_offset
// is read): ReadLocalScans streams them.
enum class LocalMapParts { kAll, kWithoutCorrespondences, kWithoutScans };

// Flat arrays laid out exactly as in the file (row-major).
struct LocalMapData {
  PinholeCamera camera;
  CameraChoice camera_choice;  // camera_index / camera_offset (camera 0 when absent)
  Trajectory keyframes;        // Refined world_from_cam0 of each keyframe.
  std::vector<int32_t> imls_n, imls_c;
  std::vector<double> imls_p_x, imls_p_y, imls_normal;  // L x 3 each.
  std::vector<double> mappoint_position;                // M x 3.
  std::vector<int64_t> scan_offset;                     // K + 1, rows of scan_points.
  std::vector<float> scan_points, scan_normals;         // S x 3 each.
  std::vector<int64_t> stats_frame;
  std::vector<int32_t> stats_visual_residuals, stats_imls_residuals;
  std::vector<double> stats_cost_before, stats_cost_after, stats_time_ms;
  Trajectory prior;
  nlohmann::json summary = nlohmann::json::object();

  size_t num_correspondences() const { return imls_n.size(); }
  size_t num_mappoints() const { return mappoint_position.size() / 3; }
  size_t num_scan_points() const { return scan_points.size() / 3; }
  // Sizes agree and indices are in range; throws naming `what`. With kWithoutScans the points
  // and normals are not expected (scan_offset is still checked but for its last value).
  void Check(const std::string& what, LocalMapParts parts = LocalMapParts::kAll) const;
};

void WriteLocalMap(const std::string& path, const LocalMapData& data, const Provenance& provenance);
LocalMapData ReadLocalMap(const std::string& path, LocalMapParts parts = LocalMapParts::kAll);

// Receives one keyframe's stored scan: `rows` points and unit normals, float x y z rows in the
// keyframe's own frame, valid only during the call.
using LocalScanSink = std::function<void(size_t keyframe, const float* points,
                                         const float* normals, size_t rows)>;

// The stored scans of a local artifact, handed to `sink` keyframe by keyframe in keyframe order,
// read a block of keyframes (about `rows_per_block` points, at least one keyframe) at a time: the
// scans/ datasets are never held whole, so a reader that keeps the scans in its own layout needs
// their size once, not twice (global_opt on a 4500-frame drive: 22.5 million points, 540 MB).
// Checks the offsets against the datasets' shapes and throws naming the file.
void ReadLocalScans(const std::string& path, const LocalScanSink& sink,
                    int64_t rows_per_block = int64_t{1} << 20);

}  // namespace jvl::io
