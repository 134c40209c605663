// The "visual" artifact (schema "visual" v1, schemas/visual.schema.json): the visual map built by
// visual_assoc from the prior poses (Sec. 4.1) and read by local and global optimisation:
//
//   camera double[6] (fx fy cx cy width height); attribute "orb" {scale_factor, num_levels};
//   keyframes/{frames, poses}                  trajectory group: keyframe frame ids + prior poses
//   keypoints/{keyframe int32[P], uv float[P,2], octave int32[P], angle float[P],
//              descriptor uint8[P,32]}          all keypoints of all keyframes, grouped by keyframe
//   mappoints/{position double[M,3], descriptor uint8[M,32], normal double[M,3]}
//   observations/{keyframe int32[O], keypoint int32[O], mappoint int32[O]}  (row indices)
//   covisibility/{edges int32[E,2], weight int32[E]}  (weight = shared map points)
//   prior/{frames, poses, timestamps}          the full prior trajectory
//   attribute "summary" (JSON)
//
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/camera.h"
#include "geometry/trajectory.h"
#include "io/artifact.h"

namespace jvl::io {

inline constexpr const char* kVisualSchema = "visual";
inline constexpr int kVisualSchemaVersion = 1;

// What ReadVisualMap reads. kWithoutDescriptors leaves keypoint_descriptor and
// mappoint_descriptor empty: the stages after visual_assoc (local_map, global_opt) use the
// keypoints' positions and octaves only, and the descriptors take 32 bytes for each of the
// millions of keypoints of a long drive.
enum class VisualMapParts { kAll, kWithoutDescriptors };

// Flat arrays laid out exactly as in the file (row-major).
struct VisualMapData {
  PinholeCamera camera;
  CameraChoice camera_choice;  // camera_index / camera_offset (camera 0 when absent)
  double scale_factor = 1.2;   // ORB pyramid: keypoint sigma = scale_factor^octave px.
  int num_levels = 8;
  Trajectory keyframes;  // Keyframe frame ids and their prior world_from_cam0 poses.
  std::vector<int32_t> keypoint_keyframe;
  std::vector<float> keypoint_uv;  // P x 2
  std::vector<int32_t> keypoint_octave;
  std::vector<float> keypoint_angle;         // Degrees.
  std::vector<uint8_t> keypoint_descriptor;  // P x 32
  std::vector<double> mappoint_position;     // M x 3, world.
  std::vector<uint8_t> mappoint_descriptor;  // M x 32
  std::vector<double> mappoint_normal;       // M x 3, unit mean viewing direction.
  std::vector<int32_t> observation_keyframe, observation_keypoint, observation_mappoint;
  std::vector<int32_t> covisibility_edges;  // E x 2, keyframe rows, first < second.
  std::vector<int32_t> covisibility_weight;
  Trajectory prior;
  nlohmann::json summary = nlohmann::json::object();

  size_t num_keypoints() const { return keypoint_keyframe.size(); }
  size_t num_mappoints() const { return mappoint_position.size() / 3; }
  size_t num_observations() const { return observation_mappoint.size(); }
  size_t num_edges() const { return covisibility_weight.size(); }
  // Sizes agree and all indices are in range; throws naming `what`. With kWithoutDescriptors
  // both descriptor arrays must be empty.
  void Check(const std::string& what, VisualMapParts parts = VisualMapParts::kAll) const;
  // Connected parts of the covisibility graph: the frame of the first keyframe of each part, in
  // keyframe order (one entry when the graph is connected, none without keyframes).
  std::vector<int64_t> CovisibilityPartStarts() const;
};

// Logs a warning naming `path` when the covisibility graph has more than one part (keyframes of
// different parts share no map point; only the LiDAR terms join them).
void WarnIfCovisibilitySplit(const VisualMapData& data, const std::string& path);

void WriteVisualMap(const std::string& path, const VisualMapData& data,
                    const Provenance& provenance);
VisualMapData ReadVisualMap(const std::string& path, VisualMapParts parts = VisualMapParts::kAll);
// Only camera_choice, scale_factor, num_levels and keyframes of a visual map, the rest left empty
// (a fraction of a second where the whole map can take seconds).
VisualMapData ReadVisualMapHeader(const std::string& path);
// The header, the camera and the keypoints of the keyframes at `frames` (frames the map lacks are
// skipped), in the map's row order; map points, observations, covisibility and the prior stay
// empty. Only the chunks of keypoints/* holding those rows are decompressed, so a few keyframes of
// a large map are read in a fraction of the whole map's time.
VisualMapData ReadVisualKeypoints(const std::string& path, const std::vector<int64_t>& frames);

}  // namespace jvl::io
