// The visual map while it is built: keyframes with their ORB features and prior poses, map points
// with their observations (ORB-SLAM2's map, without the pose optimisation), and its export to the
// flat "visual" artifact layout.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "geometry/trajectory.h"
#include "vision/guided_matching.h"
#include "vision/orb_features.h"
#include "vision/patch_align.h"

namespace jvl::mapping {

struct Observation {
  int keyframe = -1;
  int keypoint = -1;
};

struct MapPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // World.
  vision::Descriptor descriptor{};  // Most representative observation (min median distance).
  float reference_angle = 0;        // Keypoint angle of that observation (orientation check).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // Mean unit viewing direction.
  double min_distance = 0, max_distance = 0;          // Scale invariance range (m).
  std::vector<Observation> observations;              // Ordered by keyframe.
  int created_keyframe = -1;
  int visible = 1, found = 1;  // Times predicted inside a frame / matched there (culling).
  // Reference patch (from the creating keyframe) that later observations are aligned to.
  vision::PatchTemplate patch;
  int patch_keyframe = -1, patch_octave = 0;
  bool bad = false;
};

struct Keyframe {
  int64_t frame = 0;
  Rigid3d world_from_cam;
  Rigid3d cam_from_world;
  vision::OrbFeatures features;
  std::vector<int> mappoint;  // Per keypoint: map point index or -1.
  bool has_direction = false;
};

struct VisualMap {
  PinholeCamera camera;
  vision::OrbOptions orb;
  std::vector<double> level_scales;
  std::vector<Keyframe> keyframes;
  std::vector<MapPoint> points;
};

// Recomputes the normal, scale invariance range and representative descriptor of a point from
// its observations (ORB-SLAM2 MapPoint::UpdateNormalAndDepth, ComputeDistinctiveDescriptors).
void UpdatePointGeometry(VisualMap* map, int point);

// Adds an observation of `point` by keypoint `keypoint` of keyframe `keyframe`.
void AddObservation(VisualMap* map, int point, int keyframe, int keypoint);

// Marks a point bad and detaches it from its keyframes.
void RemovePoint(VisualMap* map, int point);

// Predicted pyramid level of a point seen at distance `distance` (ORB-SLAM2 PredictScale).
int PredictOctave(const MapPoint& point, double distance, const VisualMap& map);

// Projects `points` into a view (ORB-SLAM2 Frame::isInFrustum): in front of the camera, inside
// the image, within 0.8-1.2 x the scale invariance range and at most acos(min_view_cos) off the
// mean viewing direction. Returns the predictions; predicted[i] is the map point of row i.
std::vector<vision::ProjectedPoint> PredictInView(const VisualMap& map,
                                                  const std::vector<int>& points,
                                                  const Rigid3d& cam_from_world,
                                                  double min_view_cos, std::vector<int>* predicted);

struct CovisibilityEdge {
  int a = 0, b = 0;  // Keyframe rows, a < b.
  int weight = 0;    // Map points observed by both.
};
// All keyframe pairs sharing at least min_weight map points, ordered by (a, b).
std::vector<CovisibilityEdge> Covisibility(const VisualMap& map, int min_weight);

}  // namespace jvl::mapping
