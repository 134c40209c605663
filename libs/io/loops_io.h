// The "loops" artifact (schema loops v2, schemas/loops.schema.json) written by loop_detect: the
// keyframes searched and every verified loop candidate, accepted or not, with its relative pose,
// scores and the detector that proposed it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/rigid3.h"
#include "io/artifact.h"

namespace jvl::io {

constexpr char kLoopsSchema[] = "loops";
constexpr int kLoopsSchemaVersion = 2;

// A visual loop's 3D-2D match (PnP inlier): a point of the match keyframe (cam0 frame) and where
// the match and the query images see it.
struct LoopPointRecord {
  Eigen::Vector3d p_match = Eigen::Vector3d::Zero();
  Eigen::Vector2d match_uv = Eigen::Vector2d::Zero(), query_uv = Eigen::Vector2d::Zero();
  int32_t match_octave = 0, query_octave = 0;
};

// One verified candidate, as stored (plain values, independent of the loop library).
struct LoopRecord {
  int64_t query = 0;         // The later keyframe (dataset frame) ...
  int64_t match = 0;         // ... and the earlier one it was matched to.
  int32_t detector = 0;      // 0 = LiDAR descriptor, 1 = visual words, 2 = proximity.
  int32_t status = 0;        // 0 = accepted; > 0: why not (LoopStatus of libs/loop).
  Rigid3d match_from_query;  // cam0 frames.
  // LiDAR: descriptor distance (0 = identical); visual: bag-of-words score (1 = identical);
  // proximity: 0 (none).
  double score = 0;
  double ring_key_distance = 0;
  double yaw_deg = 0;  // Detector's yaw estimate of the query relative to the match.
  int32_t correspondences = 0;
  int32_t inliers = 0;  // Visual: PnP inliers (0 for the LiDAR detector) ...
  // ... stored for the accepted loops (status 0 and 8; empty otherwise and for LiDAR loops).
  std::vector<LoopPointRecord> points;
  double residual = 0;  // m, RMS IMLS distance after registration.
};

struct LoopsData {
  std::vector<int64_t> keyframes;  // Frames searched, increasing.
  std::vector<LoopRecord> loops;   // Ordered by query.
  // The camera of the loop points' pixels (loop_detect --camera; camera 0 when absent).
  CameraChoice camera_choice;
};

void WriteLoopsArtifact(const std::string& path, const LoopsData& data,
                        const Provenance& provenance);
// Reads and checks the layout (lengths agree, frames are keyframes, match < query).
LoopsData ReadLoopsArtifact(const std::string& path);

// CSV: header "query,match,detector,status,score,ring_key_distance,yaw_deg,correspondences,
// inliers,residual,tx,ty,tz" (tx, ty, tz: translation of match_from_query), shortest round-trip
// numbers.
std::string FormatLoopsCsv(const LoopsData& data);
void WriteLoopsCsv(const std::string& path, const LoopsData& data);

}  // namespace jvl::io
