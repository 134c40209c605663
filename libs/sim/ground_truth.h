// Ground-truth vanishing points: projections of the road direction and of the axes of the
// buildings in view (Sec. 4.3: a VP is K R d for a scene direction d).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "sim/scene.h"

namespace jvl::sim {

enum class VpKind { kRoad = 0, kBuildingAlong = 1, kBuildingAcross = 2, kVertical = 3 };
const char* ToString(VpKind kind);

struct GtVanishingPoint {
  VpKind kind = VpKind::kRoad;
  int group = -1;                 // Building axis group (-1 for road and vertical).
  Eigen::Vector3d direction_cam;  // Unit, camera frame, sign chosen so that z >= 0.
  Eigen::Vector2d uv;  // Pixel position; NaN when the direction is parallel to the image.
  bool in_image = false;
  int buildings = 0;  // Buildings of the group in view (0 for road/vertical).
};

// map_from_cam: camera pose in the map frame; s: the vehicle's arc length on the route.
std::vector<GtVanishingPoint> ComputeGroundTruthVps(const Scene& scene, const PinholeCamera& camera,
                                                    const Rigid3d& map_from_cam, double s);

// Projection of a camera-frame direction (uv NaN when |z| is tiny); flips d to z >= 0.
GtVanishingPoint ProjectDirection(const PinholeCamera& camera, Eigen::Vector3d d_cam);

}  // namespace jvl::sim
