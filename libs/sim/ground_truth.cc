#include "sim/ground_truth.h"

#include <cmath>
#include <limits>
#include <map>

namespace jvl::sim {

const char* ToString(VpKind kind) {
  switch (kind) {
    case VpKind::kRoad:
      return "road";
    case VpKind::kBuildingAlong:
      return "building_along";
    case VpKind::kBuildingAcross:
      return "building_across";
    case VpKind::kVertical:
      return "vertical";
  }
  return "?";
}

GtVanishingPoint ProjectDirection(const PinholeCamera& camera, Eigen::Vector3d d_cam) {
  GtVanishingPoint vp;
  d_cam.normalize();
  if (d_cam.z() < 0) d_cam = -d_cam;
  vp.direction_cam = d_cam;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (d_cam.z() > 1e-9) {
    vp.uv = camera.Project(d_cam);
    vp.in_image = camera.InImage(vp.uv);
  } else {
    vp.uv = Eigen::Vector2d(nan, nan);
  }
  return vp;
}

namespace {

// A building is in view when one of its corners, edge midpoints or its centre (at three
// heights) projects into the image at 1-120 m in front. Occlusion is not considered.
bool BuildingInView(const Building& b, const Terrain& terrain, const PinholeCamera& camera,
                    const Rigid3d& cam_from_map) {
  const auto c = b.Corners();
  std::vector<Eigen::Vector2d> pts(c.begin(), c.end());
  for (int i = 0; i < 4; ++i) pts.push_back((c[i] + c[(i + 1) % 4]) / 2);
  pts.push_back(b.center);
  const double ground = terrain.Height(b.center.x(), b.center.y());
  for (const auto& p : pts) {
    for (double f : {0.1, 0.5, 0.9}) {
      const Eigen::Vector3d q = cam_from_map * Eigen::Vector3d(p.x(), p.y(), ground + f * b.height);
      if (q.z() > 1 && q.z() < 120 && camera.InImage(camera.Project(q))) return true;
    }
  }
  return false;
}

}  // namespace

std::vector<GtVanishingPoint> ComputeGroundTruthVps(const Scene& scene, const PinholeCamera& camera,
                                                    const Rigid3d& map_from_cam, double s) {
  const Rigid3d cam_from_map = map_from_cam.Inverse();
  const Eigen::Matrix3d R = cam_from_map.RotationMatrix();
  std::vector<GtVanishingPoint> out;
  // Road direction: the centre-line tangent at s, climbing with the terrain slope.
  const RoadPoint rp = scene.route.At(s);
  const Eigen::Vector2d t(std::cos(rp.heading), std::sin(rp.heading));
  const Eigen::Vector2d g = scene.terrain.Gradient(rp.position.x(), rp.position.y());
  GtVanishingPoint road = ProjectDirection(camera, R * Eigen::Vector3d(t.x(), t.y(), g.dot(t)));
  road.kind = VpKind::kRoad;
  out.push_back(road);
  std::map<int, int> in_view;  // Axis group -> buildings in view (ordered by group).
  const Eigen::Vector3d cam_pos = map_from_cam.translation();
  for (const Building& b : scene.buildings) {
    if ((b.center - cam_pos.head<2>()).norm() > 150) continue;
    if (BuildingInView(b, scene.terrain, camera, cam_from_map)) ++in_view[b.axis_group];
  }
  for (const auto& [group, count] : in_view) {
    // "Along" is the group axis closer to the road direction at the vehicle.
    double yaw = scene.axis_group_yaw[group];
    if (std::abs(std::cos(yaw - rp.heading)) < std::abs(std::sin(yaw - rp.heading))) {
      yaw += 1.5707963267948966;
    }
    for (VpKind kind : {VpKind::kBuildingAlong, VpKind::kBuildingAcross}) {
      const double a = kind == VpKind::kBuildingAlong ? yaw : yaw + 1.5707963267948966;
      GtVanishingPoint vp =
          ProjectDirection(camera, R * Eigen::Vector3d(std::cos(a), std::sin(a), 0));
      vp.kind = kind;
      vp.group = group;
      vp.buildings = count;
      out.push_back(vp);
    }
  }
  GtVanishingPoint up = ProjectDirection(camera, R * Eigen::Vector3d::UnitZ());
  up.kind = VpKind::kVertical;
  out.push_back(up);
  return out;
}

}  // namespace jvl::sim
