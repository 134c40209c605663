#include "sim/describe.h"

#include <algorithm>
#include <cmath>

namespace jvl::sim {
namespace {

nlohmann::json Vec(const Eigen::Vector2d& v) { return {v.x(), v.y()}; }
nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json Matrix4(const Rigid3d& t) {
  const Eigen::Matrix4d m = t.Matrix4();
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

nlohmann::json BoxJson(const Box& b) {
  return {{"center", Vec(b.center)}, {"yaw_rad", b.yaw}, {"size", Vec(b.size)}};
}

void AddObjects(const Scene& sc, nlohmann::json& j) {
  nlohmann::json poles = nlohmann::json::array(), signs = nlohmann::json::array();
  nlohmann::json cars = nlohmann::json::array(), plants = nlohmann::json::array();
  nlohmann::json moving = nlohmann::json::array();
  for (const Pole& p : sc.poles) {
    poles.push_back({{"base", Vec(p.base)}, {"radius", p.radius}, {"height", p.height}});
  }
  for (const Box& s : sc.signs) signs.push_back(BoxJson(s));
  for (const Box& c : sc.parked_cars) cars.push_back(BoxJson(c));
  for (const Plant& p : sc.plants) {
    plants.push_back({{"center", Vec(p.center)}, {"radius", p.radius}, {"tree", p.tree}});
  }
  for (const MovingCar& m : sc.moving_cars) {
    moving.push_back(
        {{"s0", m.s0}, {"speed_mps", m.speed}, {"lateral", m.lateral}, {"size", Vec(m.size)}});
  }
  j["poles"] = poles;
  j["signs"] = signs;
  j["parked_cars"] = cars;
  j["plants"] = plants;
  j["moving_cars"] = moving;
}

}  // namespace

RouteSummary SummarizeRoute(const World& world) {
  RouteSummary r;
  const auto& gt = world.ground_truth;
  r.min_speed = 1e9;
  for (size_t k = 1; k < gt.size(); ++k) {
    const double d =
        (gt.world_from_cam[k].translation() - gt.world_from_cam[k - 1].translation()).norm();
    r.driven_length_m += d;
    const double v = d / (gt.timestamps[k] - gt.timestamps[k - 1]);
    r.min_speed = std::min(r.min_speed, v);
    r.max_speed = std::max(r.max_speed, v);
  }
  if (gt.size() < 2) r.min_speed = 0;
  r.duration_s = gt.empty() ? 0 : gt.timestamps.back() - gt.timestamps.front();
  r.mean_speed = r.duration_s > 0 ? r.driven_length_m / r.duration_s : 0;
  const double s_end = gt.empty() ? 0 : DriveArcLength(world.drive, gt.timestamps.back());
  for (const RoadPiece& p : world.scene.route.pieces()) {
    if (p.lead) continue;
    if (p.s0 + p.length > s_end + 1e-6) break;
    if (p.IsStraight()) {
      r.straights_100m += p.length >= 100 ? 1 : 0;
    } else {
      ++r.turns;
      r.sharp_turns += std::abs(p.curvature) > 1.0 / 50 ? 1 : 0;
    }
  }
  return r;
}

nlohmann::json DescribeScene(const World& world) {
  const Scene& sc = world.scene;
  const Rigid3d world_from_map = world.map_from_world.Inverse();
  const Eigen::Matrix3d R = world_from_map.RotationMatrix();
  const RouteSummary rs = SummarizeRoute(world);
  nlohmann::json j;
  j["scenario"] = ToString(world.options.scenario);
  j["seed"] = world.options.seed;
  j["laps"] = world.options.laps;
  j["frames"] = world.ground_truth.size();
  j["map_frame"] = "x east, y north, z up (m); poses use world = cam0 of frame 0";
  j["world_from_map"] = Matrix4(world_from_map);
  j["summary"] = {{"driven_length_m", rs.driven_length_m},
                  {"duration_s", rs.duration_s},
                  {"mean_speed_mps", rs.mean_speed},
                  {"min_speed_mps", rs.min_speed},
                  {"max_speed_mps", rs.max_speed},
                  {"straights_ge_100m", rs.straights_100m},
                  {"turns", rs.turns},
                  {"sharp_turns", rs.sharp_turns},
                  {"stop_at_s", world.options.drive.stop_at_s},
                  {"steer_transition_m", world.options.drive.steer_transition},
                  {"body_vibration_deg", world.options.drive.body_vibration}};
  nlohmann::json pieces = nlohmann::json::array();
  for (const RoadPiece& p : sc.route.pieces()) {
    pieces.push_back({{"type", p.IsStraight() ? "straight" : "arc"},
                      {"s0", p.s0},
                      {"length", p.length},
                      {"curvature", p.curvature},
                      {"start", Vec(p.start)},
                      {"start_heading_rad", p.start_heading},
                      {"speed_mps", p.speed},
                      {"open", p.open},
                      {"repeat", p.repeat},
                      {"lead", p.lead}});
  }
  j["route"] = {{"length_m", sc.route.length()},
                {"drive_begin_m", sc.route.drive_begin()},
                {"drive_end_m", sc.route.drive_end()},
                {"road_beyond_m", world.options.road_beyond},
                {"pieces", pieces},
                {"half_width_m", sc.options.road_half_width},
                {"lane_width_m", 3.5},
                {"sidewalk_width_m", sc.options.sidewalk_width}};
  const CameraOptions& cam = world.options.camera;
  j["camera"] = {{"pixel_noise", cam.pixel_noise},
                 {"exposure_variation", cam.exposure_variation},
                 {"blur_sigma", cam.blur_sigma},
                 {"supersample", cam.supersample},
                 {"supersample_contrast", cam.supersample_contrast}};
  j["vegetation"] = {{"foliage_density", sc.options.foliage_density},
                     {"hedge_coverage", sc.options.HedgeCoverage()}};
  j["terrain"] = {{"scale", sc.options.terrain_scale},
                  {"amplitude", sc.terrain.amplitude},
                  {"wavelength", sc.terrain.wavelength},
                  {"phase", sc.terrain.phase}};
  nlohmann::json groups = nlohmann::json::array();
  for (size_t g = 0; g < sc.axis_group_yaw.size(); ++g) {
    const double y = sc.axis_group_yaw[g];
    groups.push_back(
        {{"id", g},
         {"yaw_rad", y},
         {"along_world", Vec(Eigen::Vector3d(R * Eigen::Vector3d(std::cos(y), std::sin(y), 0)))},
         {"across_world",
          Vec(Eigen::Vector3d(R * Eigen::Vector3d(-std::sin(y), std::cos(y), 0)))}});
  }
  j["axis_groups"] = groups;
  j["up_world"] = Vec(Eigen::Vector3d(R * Eigen::Vector3d::UnitZ()));
  nlohmann::json b = nlohmann::json::array();
  for (size_t i = 0; i < sc.buildings.size(); ++i) {
    const Building& x = sc.buildings[i];
    b.push_back({{"id", i},
                 {"center", Vec(x.center)},
                 {"yaw_rad", x.yaw},
                 {"length", x.length},
                 {"depth", x.depth},
                 {"height", x.height},
                 {"base_z", x.base_z},
                 {"floors", x.floors},
                 {"floor_height", x.floor_height},
                 {"axis_group", x.axis_group}});
  }
  j["buildings"] = b;
  AddObjects(sc, j);
  const LidarOptions& l = world.options.lidar;
  j["lidar"] = {{"beams", l.beams},
                {"elevation_max_deg", l.elevation_max_deg},
                {"elevation_min_deg", l.elevation_min_deg},
                {"azimuth_steps", l.azimuth_steps},
                {"max_range", l.max_range},
                {"range_noise", l.range_noise},
                {"dropout", l.dropout},
                {"motion_distortion", l.motion_distortion},
                {"elevation_bias_deg", l.elevation_bias_deg},
                {"height_m", world.options.lidar_height}};
  // Recorded only when not the nominal one (scene.json of nominal drives stays as it was).
  if (l.beam_table == BeamTable::kKitti04) j["lidar"]["beam_table"] = "kitti04";
  if (world.options.calib_error_deg != 0 || world.options.calib_error_m != 0) {
    const Rigid3d error = WrittenCalibrationError(world.options);
    j["calibration_error"] = {
        {"rotation_deg", world.options.calib_error_deg},
        {"translation_m", world.options.calib_error_m},
        {"written_cam0_from_true_cam0", Matrix4(error)},
        {"true_cam0_from_velo", Matrix4(world.options.calibration.cam0_from_velo)}};
  }
  j["mesh"] = {{"triangles", sc.mesh.triangles.size()}, {"faces", sc.mesh.faces.size()}};
  return j;
}

}  // namespace jvl::sim
