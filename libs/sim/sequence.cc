#include "sim/sequence.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/threads.h"
#include "sim/random.h"

namespace jvl::sim {

Calibration KittiCalibration() {
  // KITTI odometry sequence 04, calib.txt (rectified projections and Tr = cam0_from_velo).
  const double p[4][12] = {
      {707.0912, 0, 601.8873, 0, 0, 707.0912, 183.1104, 0, 0, 0, 1, 0},
      {707.0912, 0, 601.8873, -379.8145, 0, 707.0912, 183.1104, 0, 0, 0, 1, 0},
      {707.0912, 0, 601.8873, 46.88783, 0, 707.0912, 183.1104, 0.1178601, 0, 0, 1, 0.006203223},
      {707.0912, 0, 601.8873, -333.4597, 0, 707.0912, 183.1104, 1.930130, 0, 0, 1, 0.003318498}};
  const double tr[12] = {-1.857739385241e-03, -9.999659513510e-01, -8.039975204516e-03,
                         -4.784029760483e-03, -6.481465826011e-03, 8.051860151134e-03,
                         -9.999466081774e-01, -7.337429464231e-02, 9.999773098287e-01,
                         -1.805528627661e-03, -6.496203536139e-03, -3.339968064433e-01};
  Calibration c;
  for (int i = 0; i < 4; ++i) {
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 4; ++k) c.P[i](r, k) = p[i][4 * r + k];
    }
  }
  Eigen::Matrix<double, 3, 4> m;
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 4; ++k) m(r, k) = tr[4 * r + k];
  }
  c.cam0_from_velo = Rigid3d::FromMatrix(m);
  c.image_width = 1226;
  c.image_height = 370;
  return c;
}

void SequenceOptions::Check() const {
  JVL_CHECK(frames >= 0, "frames must be >= 0 (0 = whole route), got " << frames);
  JVL_CHECK(lidar_height > 0.5 && lidar_height < 5,
            "lidar_height must be in (0.5, 5) m, got " << lidar_height);
  JVL_CHECK(calibration.image_width > 0 && calibration.image_height > 0,
            "calibration has no image size");
  JVL_CHECK(std::isfinite(road_beyond) && road_beyond >= 0 && road_beyond <= 1000,
            "road_beyond must be in [0, 1000] m, got " << road_beyond);
  JVL_CHECK(std::isfinite(calib_error_deg) && calib_error_deg >= 0 && calib_error_deg <= 10,
            "calib_error_deg must be in [0, 10] deg, got " << calib_error_deg);
  JVL_CHECK(std::isfinite(calib_error_m) && calib_error_m >= 0 && calib_error_m <= 1,
            "calib_error_m must be in [0, 1] m, got " << calib_error_m);
  drive.Check();
  scene.Check();
  lidar.Check();
  camera.Check();
  JVL_CHECK(!cameras.empty() || !render_images, "no camera to render");
  for (size_t i = 0; i < cameras.size(); ++i) {
    JVL_CHECK(cameras[i] >= 0 && cameras[i] < 4, "camera " << cameras[i] << " is not 0..3");
    for (size_t j = 0; j < i; ++j)
      JVL_CHECK(cameras[i] != cameras[j], "camera " << cameras[i] << " is listed twice");
    calibration.CheckCamera(cameras[i], "the calibration");
  }
}

Rigid3d WrittenCalibrationError(const SequenceOptions& options) {
  if (options.calib_error_deg == 0 && options.calib_error_m == 0) return Rigid3d();
  // Its own stream of the seed: the world and the noise do not change with the error.
  Rng rng(options.seed ^ 0xca11b0a7e5ULL);
  auto unit = [&rng] {
    // Uniform on the sphere.
    const double z = rng.Uniform(-1, 1), phi = rng.Uniform(0, 2 * 3.14159265358979323846);
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    return Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
  };
  const Eigen::Vector3d axis = unit(), direction = unit();
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(
                     options.calib_error_deg * 3.14159265358979323846 / 180, axis)),
                 options.calib_error_m * direction);
}

Calibration WrittenCalibration(const SequenceOptions& options) {
  Calibration written = options.calibration;
  written.cam0_from_velo = WrittenCalibrationError(options) * options.calibration.cam0_from_velo;
  return written;
}

Rigid3d World::MapFromVeloAt(double t) const {
  const Rigid3d map_from_base =
      VehiclePose(scene.route, scene.terrain, drive, options.drive, t, options.seed);
  return map_from_base *
         Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, options.lidar_height));
}

Trajectory World::MapFromCam() const {
  Trajectory t = ground_truth;
  for (auto& p : t.world_from_cam) p = map_from_world * p;
  return t;
}

std::unique_ptr<World> BuildWorld(const SequenceOptions& options) {
  options.Check();
  auto world = std::make_unique<World>();
  world->options = options;
  // The drive starts at the map origin heading 0.35 rad; the lead piece before it starts
  // road_beyond metres back.
  constexpr double kHeading = 0.35;
  const Route route(WithLeads(ScenarioRoute(options.scenario, options.laps), options.road_beyond),
                    -options.road_beyond * Eigen::Vector2d(std::cos(kHeading), std::sin(kHeading)),
                    kHeading);
  SceneOptions scene_options = options.scene;
  scene_options.scenario = options.scenario;
  scene_options.seed = options.seed;
  world->scene = BuildScene(route, scene_options);
  DriveOptions drive = options.drive;
  if (options.stop) {
    int corners = 0;
    for (const RoadPiece& p : route.pieces()) {
      if (std::abs(p.curvature) > 0.05 && ++corners == 2) drive.stop_at_s = p.s0 - 12;
    }
    if (drive.stop_at_s < 0) drive.stop_at_s = (route.drive_begin() + route.drive_end()) / 2;
  }
  world->options.drive = drive;
  world->drive = PlanDrive(route, drive);
  const int64_t available =
      static_cast<int64_t>(std::floor(world->drive.duration() * drive.frame_rate_hz)) + 1;
  JVL_CHECK(options.frames <= available, "--frames " << options.frames << " exceeds the "
                                                     << available << " frames of the "
                                                     << ToString(options.scenario) << " route");
  const int64_t n = options.frames > 0 ? options.frames : available;
  const Rigid3d velo_from_cam0 = options.calibration.cam0_from_velo.Inverse();
  for (int64_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / drive.frame_rate_hz;
    const Rigid3d map_from_cam = world->MapFromVeloAt(t) * velo_from_cam0;
    if (k == 0) world->map_from_world = map_from_cam;
    world->ground_truth.Append(k, world->map_from_world.Inverse() * map_from_cam, t);
  }
  world->caster = std::make_unique<RayCaster>(world->scene.mesh);
  return world;
}

SimFrame SimulateFrame(const World& world, int64_t frame) {
  const auto index = world.ground_truth.IndexOf(frame);
  JVL_CHECK(index.has_value(), "frame " << frame << " is not part of the sequence");
  const SequenceOptions& opt = world.options;
  SimFrame out;
  out.frame = frame;
  out.time = world.ground_truth.timestamps[*index];
  const Rigid3d map_from_velo = world.MapFromVeloAt(out.time);
  const Rigid3d map_from_cam = map_from_velo * opt.calibration.cam0_from_velo.Inverse();
  std::vector<Box> moving;
  for (size_t i = 0; i < world.scene.moving_cars.size(); ++i) {
    moving.push_back(world.scene.MovingCarBox(i, out.time));
  }
  if (opt.simulate_scans) {
    const double t = out.time;
    const SweepPose sweep = [&world, t](double tau) { return world.MapFromVeloAt(t + tau); };
    out.scan = SimulateScan(world.scene, *world.caster, map_from_velo, moving, opt.lidar,
                            HashCombine(opt.seed, 2 * static_cast<uint64_t>(frame) + 1), &sweep);
  }
  const PinholeCamera camera = opt.calibration.Camera(0);
  if (opt.render_images) {
    const double gain = ExposureGain(frame, opt.camera.exposure_variation, opt.seed);
    for (const int c : opt.cameras) {
      // Camera c at its offset from camera 0 (same orientation: rectified), its own noise.
      const uint64_t seed = HashCombine(opt.seed, 2 * static_cast<uint64_t>(frame));
      const CameraChoice choice = CameraChoice::Of(opt.calibration, c);
      cv::Mat image = RenderImage(world.scene, *world.caster, opt.calibration.Camera(c),
                                  map_from_cam * choice.camera_from_cam0().Inverse(), moving, gain,
                                  c == 0 ? seed : HashCombine(seed, c), opt.camera);
      if (c == 0) {
        out.image = std::move(image);
        continue;
      }
      if (c >= 2) cv::merge(std::vector<cv::Mat>{image, image, image}, image);
      out.other_images.emplace_back(c, std::move(image));
    }
  }
  out.vps = ComputeGroundTruthVps(world.scene, camera, map_from_cam,
                                  DriveArcLength(world.drive, out.time));
  return out;
}

void GenerateSequence(const World& world, int threads,
                      const std::function<void(SimFrame&&)>& sink) {
  const auto& frames = world.ground_truth.frames;
  ParallelFor(static_cast<int64_t>(frames.size()), threads,
              [&](int64_t i) { sink(SimulateFrame(world, frames[static_cast<size_t>(i)])); });
}

}  // namespace jvl::sim
