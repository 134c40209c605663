#include "map_check_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "core/check.h"
#include "io/artifact.h"
#include "io/files.h"
#include "io/trajectory_io.h"

namespace jvl::tools {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

const nlohmann::json& Field(const nlohmann::json& j, const char* key, const std::string& what) {
  JVL_CHECK(j.is_object() && j.contains(key), what << ": no field '" << key << "'");
  return j[key];
}

// Largest position (m) and rotation (rad) difference of two trajectories with the same frames.
std::pair<double, double> MaxPoseDifference(const Trajectory& a, const Trajectory& b) {
  double position = 0, rotation = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const Rigid3d& x = a.world_from_cam[i];
    const Rigid3d& y = b.world_from_cam[i];
    position = std::max(position, (x.translation() - y.translation()).norm());
    rotation = std::max(rotation, RotationAngle(x.rotation().inverse() * y.rotation()));
  }
  return {position, rotation};
}

// Largest angle between two viewing rays of a point (degrees).
double Parallax(const std::vector<Eigen::Vector3d>& rays) {
  double min_cos = 1;
  for (size_t a = 0; a < rays.size(); ++a) {
    for (size_t b = a + 1; b < rays.size(); ++b) min_cos = std::min(min_cos, rays[a].dot(rays[b]));
  }
  return std::acos(std::clamp(min_cos, -1.0, 1.0)) * kRadToDeg;
}

}  // namespace

sim::SequenceOptions WorldOptionsFromScene(const nlohmann::json& scene, const std::string& what) {
  sim::SequenceOptions o;
  try {
    o.scenario = sim::ParseScenario(Field(scene, "scenario", what).get<std::string>());
    o.seed = Field(scene, "seed", what).get<uint64_t>();
    o.frames = Field(scene, "frames", what).get<int64_t>();
    const nlohmann::json& summary = Field(scene, "summary", what);
    o.stop = Field(summary, "stop_at_s", what).get<double>() >= 0;
    // Fields added over time; older files were written with the values of their day.
    o.laps = scene.value("laps", 1);
    o.drive.steer_transition = summary.value("steer_transition_m", 0.0);
    o.drive.body_vibration = summary.value("body_vibration_deg", 0.0);
    o.road_beyond = Field(scene, "route", what).value("road_beyond_m", 0.0);
    o.scene.moving_cars = static_cast<int>(Field(scene, "moving_cars", what).size());
    // Written since the terrain became scalable; older files have the default scale.
    o.scene.terrain_scale = Field(scene, "terrain", what).value("scale", 1.0);
    // Written since crowns became volumes of leaf clumps and the roadsides got hedges; older
    // files had opaque crowns and no hedges.
    const nlohmann::json vegetation = scene.value("vegetation", nlohmann::json::object());
    o.scene.foliage_density = vegetation.value("foliage_density", 0.0);
    o.scene.hedge_coverage = vegetation.value("hedge_coverage", 0.0);
  } catch (const nlohmann::json::exception& e) {
    JVL_THROW(what << ": unexpected scene description: " << io::JsonErrorText(e));
  }
  JVL_CHECK(o.frames > 0, what << ": no frames");
  o.render_images = false;
  o.simulate_scans = false;
  return o;
}

void CheckSameWorld(const sim::World& world, const nlohmann::json& scene,
                    const std::optional<Trajectory>& poses, const std::string& what) {
  const Eigen::Matrix4d expected = world.map_from_world.Inverse().Matrix4();
  try {
    const nlohmann::json& m = Field(scene, "world_from_map", what);
    double diff = 0;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) {
        diff = std::max(diff, std::abs(m.at(r).at(c).get<double>() - expected(r, c)));
      }
    }
    JVL_CHECK(diff < 1e-9, what << ": the rebuilt world differs (world_from_map off by " << diff
                                << "); was the sequence made by another version of sim_sequence?");
    const auto triangles = Field(Field(scene, "mesh", what), "triangles", what).get<size_t>();
    const auto buildings = Field(scene, "buildings", what).size();
    JVL_CHECK(
        triangles == world.scene.mesh.triangles.size() && buildings == world.scene.buildings.size(),
        what << ": the rebuilt world differs (" << world.scene.mesh.triangles.size()
             << " triangles, " << world.scene.buildings.size() << " buildings; the file has "
             << triangles << ", " << buildings << ")");
  } catch (const nlohmann::json::exception& e) {
    JVL_THROW(what << ": unexpected scene description: " << io::JsonErrorText(e));
  }
  if (!poses) return;
  JVL_CHECK(poses->frames == world.ground_truth.frames,
            what << ": the poses file has " << poses->size() << " frames, the world "
                 << world.ground_truth.size());
  const auto [position, rotation] = MaxPoseDifference(*poses, world.ground_truth);
  JVL_CHECK(position < 1e-6 && rotation < 1e-6,
            what << ": the rebuilt ground truth differs from the poses file by up to " << position
                 << " m, " << rotation * kRadToDeg << " deg");
}

std::unique_ptr<sim::World> RebuildSequenceWorld(const std::string& sequence_dir) {
  namespace fs = std::filesystem;
  const std::string scene_path = sequence_dir + "/sim/scene.json";
  JVL_CHECK(io::IsDirectory(sequence_dir), "--sequence " << sequence_dir << ": not a folder");
  JVL_CHECK(io::FileExists(scene_path),
            scene_path << ": file not found (--sequence must be a sim_sequence folder)");
  const nlohmann::json scene = io::ReadJsonArtifact(scene_path, "sim_scene", 1);
  auto world = sim::BuildWorld(WorldOptionsFromScene(scene, scene_path));
  const fs::path dir = fs::absolute(fs::path(sequence_dir)).lexically_normal();
  const std::string name = (dir.has_filename() ? dir : dir.parent_path()).filename().string();
  const std::string poses_path =
      ((dir.has_filename() ? dir : dir.parent_path()).parent_path().parent_path() / "poses" /
       (name + ".txt"))
          .string();
  std::optional<Trajectory> poses;
  if (io::FileExists(poses_path)) poses = io::ReadTrajectory(poses_path);
  CheckSameWorld(*world, scene, poses, scene_path);
  return world;
}

MapCheckRunResult RunMapCheck(const sim::World& world, const io::VisualMapData& visual,
                              const sim::SurfaceCheckOptions& options, int threads) {
  options.Check();
  visual.Check("visual map");
  const Trajectory& gt = world.ground_truth;
  MapCheckRunResult result;
  std::vector<Rigid3d> map_from_cam;
  std::vector<double> times;
  for (size_t k = 0; k < visual.keyframes.size(); ++k) {
    const int64_t frame = visual.keyframes.frames[k];
    const auto i = gt.IndexOf(frame);
    JVL_CHECK(i.has_value(), "visual map: keyframe frame " << frame << " is not in the sequence ("
                                                           << gt.size() << " frames)");
    const Rigid3d& pose = visual.keyframes.world_from_cam[k];
    const Rigid3d& truth = gt.world_from_cam[*i];
    result.max_keyframe_position_error_m = std::max(
        result.max_keyframe_position_error_m, (pose.translation() - truth.translation()).norm());
    result.max_keyframe_rotation_error_deg =
        std::max(result.max_keyframe_rotation_error_deg,
                 RotationAngle(truth.rotation().inverse() * pose.rotation()) * kRadToDeg);
    // The points were seen from the map's camera, at its offset from camera 0.
    map_from_cam.push_back(world.map_from_world * pose *
                           visual.camera_choice.camera_from_cam0().Inverse());
    times.push_back(gt.timestamps[*i]);
  }
  std::vector<Eigen::Vector3d> points(visual.num_mappoints());
  for (size_t p = 0; p < points.size(); ++p) {
    points[p] = world.map_from_world * Eigen::Vector3d(visual.mappoint_position[3 * p],
                                                       visual.mappoint_position[3 * p + 1],
                                                       visual.mappoint_position[3 * p + 2]);
  }
  result.views = sim::NearestViews(points, map_from_cam, times, visual.observation_keyframe,
                                   visual.observation_mappoint);
  result.distances =
      sim::MeasureSurfaceDistances(world.scene, *world.caster, result.views, threads);
  result.summary = sim::SummarizeSurfaceDistances(result.distances, options);
  return result;
}

nlohmann::json ToJson(const MapCheckRunResult& result) {
  nlohmann::json j = sim::ToJson(result.summary);
  j["max_keyframe_position_error_m"] = result.max_keyframe_position_error_m;
  j["max_keyframe_rotation_error_deg"] = result.max_keyframe_rotation_error_deg;
  return j;
}

std::vector<double> KeypointConsistency(const sim::World& world, const io::VisualMapData& visual,
                                        const std::vector<sim::PointView>& views) {
  const size_t m = visual.num_mappoints();
  std::vector<std::vector<size_t>> observations(m);
  for (size_t o = 0; o < visual.num_observations(); ++o) {
    observations[static_cast<size_t>(visual.observation_mappoint[o])].push_back(o);
  }
  std::vector<Rigid3d> map_from_cam;  // of the map's camera
  for (const Rigid3d& pose : visual.keyframes.world_from_cam) {
    map_from_cam.push_back(world.map_from_world * pose *
                           visual.camera_choice.camera_from_cam0().Inverse());
  }
  const auto uv = [&](size_t keypoint) {
    return Eigen::Vector2d(visual.keypoint_uv[2 * keypoint], visual.keypoint_uv[2 * keypoint + 1]);
  };
  std::vector<double> out(m, std::numeric_limits<double>::quiet_NaN());
  for (size_t p = 0; p < m && p < views.size(); ++p) {
    const int k = views[p].keyframe;
    const auto& obs = observations[p];
    const auto nearest = std::find_if(
        obs.begin(), obs.end(), [&](size_t o) { return visual.observation_keyframe[o] == k; });
    if (nearest == obs.end()) continue;
    // The true surface point behind the nearest keypoint.
    const Rigid3d& pose = map_from_cam[static_cast<size_t>(k)];
    const Eigen::Vector3d dir =
        (pose.RotationMatrix() *
         visual.camera.Unproject(uv(static_cast<size_t>(visual.observation_keypoint[*nearest]))))
            .normalized();
    sim::Hit hit = world.caster->Intersect(pose.translation(), dir, 1e-3, 1e4);
    std::vector<sim::Box> cars;
    for (size_t c = 0; c < world.scene.moving_cars.size(); ++c) {
      cars.push_back(world.scene.MovingCarBox(c, views[p].time));
    }
    sim::IntersectBoxes(cars, pose.translation(), dir, &hit);
    if (!hit.valid()) continue;
    const Eigen::Vector3d y = pose.translation() + hit.t * dir;
    double worst = 0;
    for (size_t o : observations[p]) {
      const size_t q = static_cast<size_t>(visual.observation_keypoint[o]);
      const Eigen::Vector3d c =
          map_from_cam[static_cast<size_t>(visual.observation_keyframe[o])].Inverse() * y;
      const double sigma = std::pow(visual.scale_factor, visual.keypoint_octave[q]);
      worst = c.z() > 0 ? std::max(worst, (visual.camera.Project(c) - uv(q)).norm() / sigma)
                        : std::numeric_limits<double>::infinity();
      if (c.z() <= 0) break;
    }
    out[p] = worst;
  }
  return out;
}

std::string FormatPointsCsv(const MapCheckRunResult& result, const sim::World& world,
                            const io::VisualMapData& visual) {
  const std::vector<double> consistency = KeypointConsistency(world, visual, result.views);
  std::vector<int> observations(visual.num_mappoints(), 0);
  std::vector<std::vector<Eigen::Vector3d>> rays(visual.num_mappoints());
  for (size_t o = 0; o < visual.observation_mappoint.size(); ++o) {
    const size_t p = static_cast<size_t>(visual.observation_mappoint[o]);
    ++observations[p];
    const Eigen::Vector3d x(visual.mappoint_position[3 * p], visual.mappoint_position[3 * p + 1],
                            visual.mappoint_position[3 * p + 2]);
    const Rigid3d world_from_camera =
        visual.keyframes.world_from_cam[static_cast<size_t>(visual.observation_keyframe[o])] *
        visual.camera_choice.camera_from_cam0().Inverse();
    rays[p].push_back((x - world_from_camera.translation()).normalized());
  }
  std::string out =
      "point,x,y,z,frame,depth,hit,surface,along_ray,perpendicular,cos_incidence,observations,"
      "parallax_deg,keypoint_error_sigma\n";
  char line[360];
  for (size_t p = 0; p < result.distances.size(); ++p) {
    const sim::SurfaceDistance& d = result.distances[p];
    const sim::PointView& v = result.views[p];
    const char* surface =
        !d.hit ? "none"
        : d.moving_car
            ? "moving_car"
            : sim::ToString(world.scene.mesh.faces[static_cast<size_t>(d.face)].material);
    const int64_t frame =
        v.keyframe >= 0 ? visual.keyframes.frames[static_cast<size_t>(v.keyframe)] : -1;
    std::snprintf(line, sizeof(line),
                  "%zu,%.4f,%.4f,%.4f,%lld,%.3f,%d,%s,%.4f,%.4f,%.4f,%d,%.3f,%.3f\n", p,
                  visual.mappoint_position[3 * p], visual.mappoint_position[3 * p + 1],
                  visual.mappoint_position[3 * p + 2], static_cast<long long>(frame),
                  std::isfinite(d.depth) ? d.depth : -1.0, d.hit ? 1 : 0, surface, d.along_ray,
                  d.perpendicular, d.cos_incidence, observations[p], Parallax(rays[p]),
                  std::isfinite(consistency[p]) ? consistency[p] : -1.0);
    out += line;
  }
  return out;
}

}  // namespace jvl::tools
