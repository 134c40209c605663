// How far the points of a visual map lie from the true scene surface (issue #8: "map points lie on
// scene surfaces, median distance <= 5 cm for depth < 30 m").
//
// Each map point is measured from one camera: the observing keyframe in which its depth is
// smallest (the view that resolves it best). A ray from that camera centre C towards the point X
// is cast against the static mesh and against the moving cars at that keyframe's time; with the
// first hit at t_hit and r = |X - C|
//   along-ray distance     a = t_hit - r   (> 0: the point is in front of the surface),
//   perpendicular distance p = |a| * |cos(ray, surface normal)|, the distance of X from the plane
//                              of the surface it projects onto.
// Everything is in the map frame of the scene (World::map_from_world maps poses into it).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "geometry/rigid3.h"
#include "sim/raycaster.h"
#include "sim/scene.h"

namespace jvl::sim {

struct SurfaceCheckOptions {
  double max_depth = 30;                             // Points deeper in their view are skipped.
  double threshold = 0.05;                           // "On the surface" (m, perpendicular).
  std::vector<double> depth_bins = {0, 10, 20, 30};  // Bin edges (m), increasing.
  void Check() const;
};

// A map point and the camera it is measured from.
struct PointView {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d camera_center = Eigen::Vector3d::Zero();
  double depth = 0;  // Along that camera's optical axis; +inf when no camera sees it in front.
  double time = 0;   // That keyframe's time (moving cars).
  int keyframe = -1;
};

// For every point, its observing keyframe with the smallest positive depth. `map_from_cam` and
// `times` are per keyframe; observation o links keyframe obs_keyframe[o] and point obs_point[o].
// Throws on indices out of range.
std::vector<PointView> NearestViews(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<Rigid3d>& map_from_cam,
                                    const std::vector<double>& times,
                                    const std::vector<int32_t>& obs_keyframe,
                                    const std::vector<int32_t>& obs_point);

struct SurfaceDistance {
  double depth = 0;
  bool hit = false;         // Some surface lies along the ray.
  bool moving_car = false;  // The hit is a moving car.
  double along_ray = 0;     // t_hit - |X - C| (0 without a hit).
  double perpendicular = 0;
  double cos_incidence = 0;  // |cos(ray, surface normal)| at the hit.
  int32_t face = -1;         // Static mesh face hit, or -1.
};

// Measures every view (depth limits are applied by the summary). Deterministic, thread-safe
// ray casts on `threads` threads.
std::vector<SurfaceDistance> MeasureSurfaceDistances(const Scene& scene, const RayCaster& caster,
                                                     const std::vector<PointView>& views,
                                                     int threads);

struct SurfaceDistanceStats {
  double min_depth = 0, max_depth = 0;  // Depth range [min, max) of the points counted.
  int64_t points = 0;                   // Points in the depth range.
  int64_t no_hit = 0;                   // Of those, nothing along the ray.
  int64_t moving_car = 0;               // Of those, measured against a moving car.
  // Over the points with a hit (NaN when there are none):
  double median_perpendicular = 0, p90_perpendicular = 0;
  double median_along = 0, p90_along = 0;  // |t_hit - r|.
  double median_signed_along = 0;          // t_hit - r: > 0 points in front of the surface.
  // Fraction of all points in range (no hit counts as off the surface) with p <= threshold.
  double within_threshold = 0;
};

struct SurfaceCheckSummary {
  int64_t total_points = 0;
  int64_t beyond_max_depth = 0;  // Skipped: depth >= max_depth (or no view in front).
  double threshold = 0;
  SurfaceDistanceStats all;                // 0 <= depth < max_depth.
  std::vector<SurfaceDistanceStats> bins;  // One per depth_bins interval.
};

SurfaceCheckSummary SummarizeSurfaceDistances(const std::vector<SurfaceDistance>& distances,
                                              const SurfaceCheckOptions& options);

nlohmann::json ToJson(const SurfaceCheckSummary& summary);

}  // namespace jvl::sim
