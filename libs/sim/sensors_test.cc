#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "lidar/preprocess.h"
#include "sim/raycaster.h"
#include "sim/road.h"
#include "sim/scene.h"
#include "sim/scene_mesh.h"
#include "sim/sequence.h"
#include "sim/shading.h"

namespace jvl::sim {
namespace {

std::unique_ptr<World> SmallWorld(double range_noise, double dropout) {
  SequenceOptions opt;
  opt.frames = 30;
  opt.seed = 7;
  opt.lidar.range_noise = range_noise;
  opt.lidar.dropout = dropout;
  return BuildWorld(opt);
}

// Every return lies on a scene surface: re-casting the ray towards the point, once its elevation
// bias (the default one) is corrected, finds a surface at the measured range, within the range
// noise.
TEST(LidarTest, ReturnsLieOnSurfacesWithinNoise) {
  for (double sigma : {0.0, 0.02}) {
    const auto world = SmallWorld(sigma, 0.0);
    SimFrame f = SimulateFrame(*world, 12);
    ASSERT_GT(f.scan.size(), 60000u);
    ASSERT_GT(world->options.lidar.elevation_bias_deg, 0.0);
    lidar::CorrectVerticalAngle(world->options.lidar.elevation_bias_deg * M_PI / 180,
                                &f.scan.points);
    const Rigid3d map_from_velo = world->MapFromVeloAt(f.time);
    std::vector<Box> moving;
    for (size_t i = 0; i < world->scene.moving_cars.size(); ++i) {
      moving.push_back(world->scene.MovingCarBox(i, f.time));
    }
    double sum2 = 0, max_err = 0;
    int n = 0, far = 0;
    for (size_t i = 0; i < f.scan.size(); i += 7) {
      const Eigen::Vector3d p = f.scan.points[i];
      const Eigen::Vector3d d = map_from_velo.RotationMatrix() * p.normalized();
      Hit hit = world->caster->Intersect(map_from_velo.translation(), d, 0.05, 130);
      IntersectBoxes(moving, map_from_velo.translation(), d, &hit);
      ASSERT_TRUE(hit.valid());
      const double e = p.norm() - hit.t;
      sum2 += e * e;
      max_err = std::max(max_err, std::abs(e));
      far += std::abs(e) > 5 * sigma + 2e-3 ? 1 : 0;
      ++n;
    }
    const double rms = std::sqrt(sum2 / n);
    if (sigma == 0) {
      EXPECT_LT(max_err, 2e-3);
    } else {
      EXPECT_NEAR(rms, sigma, 0.2 * sigma);
      EXPECT_LT(far, n / 1000 + 1);
    }
  }
}

TEST(LidarTest, BeamPatternIsHdl64Like) {
  const LidarOptions opt;
  const auto e = opt.ElevationsRad();
  ASSERT_EQ(e.size(), 64u);
  EXPECT_NEAR(e.front() * 180 / M_PI, 2.0, 1e-9);
  EXPECT_NEAR(e.back() * 180 / M_PI, -24.9, 1e-9);
  for (size_t i = 1; i < e.size(); ++i) EXPECT_LT(e[i], e[i - 1]);
  // Ground returns: the sensor is 1.73 m above the road (velodyne z ~ -1.73 close by).
  const auto world = SmallWorld(0.0, 0.0);
  const SimFrame f = SimulateFrame(*world, 0);
  int ground = 0;
  for (const auto& p : f.scan.points) {
    if (p.head<2>().norm() < 6 && std::abs(p.y()) < 2) {
      EXPECT_NEAR(p.z(), -1.73, 0.12);
      ++ground;
    }
  }
  EXPECT_GT(ground, 100);
}

// The kitti04 beam table: the real KITTI 04 rings' median elevations (2.366 to -23.696 deg) as
// reported at the default bias, so the beams fire 0.12 deg above them; the lowest ring meets
// the road 6 % farther from the sensor than the nominal table's -24.9 deg beam.
TEST(LidarTest, Kitti04BeamTableHasTheRealRingsElevations) {
  LidarOptions opt;
  opt.beam_table = BeamTable::kKitti04;
  const auto e = opt.ElevationsRad();
  ASSERT_EQ(e.size(), 64u);
  const double bias = opt.elevation_bias_deg;
  EXPECT_NEAR(bias, 0.12, 1e-12);
  EXPECT_NEAR(e.front() * 180 / M_PI - bias, 2.366, 1e-9);
  EXPECT_NEAR(e[32] * 180 / M_PI - bias, -8.408, 1e-9);
  EXPECT_NEAR(e.back() * 180 / M_PI - bias, -23.696, 1e-9);
  for (size_t i = 1; i < e.size(); ++i) EXPECT_LT(e[i], e[i - 1]);

  // Nearest road return in front of the car with each table: their distances are in the ratio
  // of the lowest beams' cotangents, tan(24.9) / tan(23.576) = 1.064 (whatever the exact height
  // of the sensor above the road there).
  double nearest[2] = {1e9, 1e9};
  for (const BeamTable table : {BeamTable::kNominal, BeamTable::kKitti04}) {
    SequenceOptions so;
    so.frames = 30;
    so.seed = 7;
    so.lidar.beam_table = table;
    const auto world = BuildWorld(so);
    const SimFrame f = SimulateFrame(*world, 0);
    double& n = nearest[table == BeamTable::kKitti04 ? 1 : 0];
    for (const auto& p : f.scan.points) {
      if (p.x() > 0 && std::abs(p.y()) < 0.5 && std::abs(p.z() + 1.73) < 0.12)
        n = std::min(n, p.head<2>().norm());
    }
  }
  EXPECT_NEAR(nearest[0], 3.73, 0.08);
  EXPECT_NEAR(nearest[1] / nearest[0],
              std::tan(24.9 * M_PI / 180) / std::tan((23.696 - 0.12) * M_PI / 180), 0.004);

  opt.beams = 32;
  EXPECT_THROW(opt.Check(), std::exception);
}

// A dark square on an empty (sky) background appears centred on the projection of its centre.
TEST(RenderTest, KnownPointProjectsToTheRightPixel) {
  const PinholeCamera cam = KittiCalibration().Camera(0);
  const Rigid3d world_from_cam(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())) *
          Eigen::Quaterniond(Eigen::AngleAxisd(-0.05, Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(5, -1, 2));
  for (const Eigen::Vector2d& target :
       {Eigen::Vector2d(900.3, 250.7), Eigen::Vector2d(201.6, 80.2)}) {
    const Eigen::Vector3d x_cam = 12.0 * cam.Unproject(target);
    Scene scene;
    // A thin 0.3 m plate facing the camera, centred on x_cam and axis-aligned in the camera
    // frame: built in the camera frame, then moved to the world.
    Mesh local;
    AddBox(local, Eigen::Vector2d(x_cam.x(), x_cam.z() + 0.001), 0.0, 0.3, 0.002, -0.15, 0.15, 0.0,
           Material::kCar, Material::kCar, -1, 0.0f);
    // Boxes are built with z up; rotate (x, y, z) -> (x, z + y_cam, y) into the camera frame.
    for (const auto& v : local.vertices) {
      const Eigen::Vector3d pc(v.x(), v.z() + x_cam.y(), v.y());
      scene.mesh.AddVertex(world_from_cam * pc);
    }
    scene.mesh.triangles = local.triangles;
    scene.mesh.triangle_face = local.triangle_face;
    scene.mesh.faces = local.faces;
    const RayCaster caster(scene.mesh);
    CameraOptions opt;
    opt.pixel_noise = 0;
    opt.blur_sigma = 0;
    const cv::Mat img = RenderImage(scene, caster, cam, world_from_cam, {}, 1.0, 1, opt);
    double su = 0, sv = 0, n = 0;
    for (int v = 0; v < img.rows; ++v) {
      for (int u = 0; u < img.cols; ++u) {
        if (img.at<uint8_t>(v, u) < 100) su += u, sv += v, n += 1;
      }
    }
    ASSERT_GT(n, 100);
    EXPECT_NEAR(su / n, target.x(), 0.3);
    EXPECT_NEAR(sv / n, target.y(), 0.3);
  }
}

// A pixel integrates the light over its area: the grey levels across a straight edge tell where
// the edge lies within the pixel, which one ray per pixel centre cannot (it quantises the edge
// to the pixel grid and the patch alignment of visual_assoc then has nothing to refine).
TEST(RenderTest, SupersamplingEncodesTheSubPixelEdgePosition) {
  const PinholeCamera cam = KittiCalibration().Camera(0);
  const Rigid3d world_from_cam;
  const double depth = 10.0;
  const int row = 180;
  CameraOptions opt;
  opt.pixel_noise = 0;
  opt.blur_sigma = 0;
  // A plate facing the camera at `z` (behind it for z < 0: sky only) from x0 to x0 + 10 m.
  const auto render = [&](double x0, double z, int supersample) {
    Scene scene;
    Mesh local;
    AddBox(local, Eigen::Vector2d(x0 + 5, z), 0.0, 10.0, 0.002, -3, 3, 0.0, Material::kCar,
           Material::kCar, -1, 0.0f);
    // Boxes are built with z up: (x, y, z) -> camera (x, z, y).
    for (const auto& v : local.vertices) scene.mesh.AddVertex(Eigen::Vector3d(v.x(), v.z(), v.y()));
    scene.mesh.triangles = local.triangles;
    scene.mesh.triangle_face = local.triangle_face;
    scene.mesh.faces = local.faces;
    const RayCaster caster(scene.mesh);
    opt.supersample = supersample;
    return RenderImage(scene, caster, cam, world_from_cam, {}, 1.0, 1, opt);
  };
  const cv::Mat sky = render(0.0, -depth, 1);
  // Edge position from the covered fraction of each pixel of one row: pixel u covers
  // [u - 0.5, u + 0.5], so the fractions of a plate reaching the right border from x_e sum to
  // (W - 0.5) - x_e.
  const auto edge = [&](double u_edge, int supersample) {
    const cv::Mat img = render(depth * (u_edge - cam.cx) / cam.fx, depth, supersample);
    const double plate = img.at<uint8_t>(row, img.cols - 5);
    double covered = 0;
    for (int u = 0; u < img.cols; ++u) {
      const double background = sky.at<uint8_t>(row, u);
      covered +=
          std::clamp((background - img.at<uint8_t>(row, u)) / (background - plate), 0.0, 1.0);
    }
    return (img.cols - 0.5) - covered;
  };
  double worst_point = 0, worst_2 = 0, worst_3 = 0;
  for (double u = 600.0; u < 601.0; u += 0.0625) {
    worst_point = std::max(worst_point, std::abs(edge(u, 1) - u));
    worst_2 = std::max(worst_2, std::abs(edge(u, 2) - u));
    worst_3 = std::max(worst_3, std::abs(edge(u, 3) - u));
  }
  // The rotated grid puts the ss x ss rays in ss^2 different columns: the covered fraction of a
  // vertical edge comes in steps of 1 / ss^2, so the edge is found within 1 / (2 ss^2) px (plus
  // grey-level rounding); a plain 2 x 2 grid would be off by up to 1/4 px.
  EXPECT_LT(worst_2, 0.14);
  EXPECT_LT(worst_3, 0.07);
  EXPECT_GT(worst_point, 0.4);  // One ray: anywhere within the pixel.
  std::printf("edge position error: 1 ray %.3f px, 2 x 2 %.3f px, 3 x 3 %.3f px\n", worst_point,
              worst_2, worst_3);
}

// Texture noise finer than the sensor's footprint averages out within one sample (as a pixel
// integrates it): the fine octaves fade, the coarse ones stay, the mean stays.
TEST(ShadingTest, NoiseFinerThanTheFootprintAveragesOut) {
  const auto world = SmallWorld(0.0, 0.0);
  const Scene& scene = world->scene;
  Hit hit;
  for (size_t i = 0; i < scene.mesh.faces.size() && hit.face < 0; ++i) {
    if (scene.mesh.faces[i].material == Material::kGround) hit.face = static_cast<int32_t>(i);
  }
  ASSERT_GE(hit.face, 0);
  // Grass beside the road: 200 points 1 cm apart along it, 12 m to the left of the centre line.
  const RoadPoint r = scene.route.At(20.0);
  const Eigen::Vector2d along(std::cos(r.heading), std::sin(r.heading));
  const Eigen::Vector2d left(-along.y(), along.x());
  const auto albedo = [&](int k, double footprint) {
    const Eigen::Vector2d q = r.position + 12.0 * left + 0.01 * k * along;
    return static_cast<double>(ShadeSurface(scene, hit, {q.x(), q.y(), 0.0}, footprint).albedo);
  };
  // Mean absolute step between neighbours (fine detail) and the spread of the values.
  const auto stats = [&](double footprint, double* step, double* spread) {
    double lo = 1, hi = 0;
    *step = 0;
    for (int k = 0; k < 200; ++k) {
      const double a = albedo(k, footprint);
      lo = std::min(lo, a);
      hi = std::max(hi, a);
      if (k > 0) *step += std::abs(a - albedo(k - 1, footprint)) / 199;
    }
    *spread = hi - lo;
  };
  double step_point, spread_point, step_pixel, spread_pixel, step_far, spread_far;
  stats(0.0, &step_point, &spread_point);  // A point sample: every octave.
  stats(0.1, &step_pixel, &spread_pixel);  // 10 cm footprint: the 7 / m octave is gone.
  stats(10.0, &step_far, &spread_far);     // Every octave is finer than the footprint.
  EXPECT_GT(spread_point, 0.01);
  EXPECT_LT(step_pixel, 0.5 * step_point);
  EXPECT_GT(spread_pixel, 0.0);
  EXPECT_EQ(spread_far, 0.0);
  EXPECT_NEAR(albedo(0, 10.0), 0.32, 1e-6);  // The grass albedo without noise: the mean.
}

TEST(RenderTest, FeaturesLandOnStructure) {
  const auto world = SmallWorld(0.02, 0.02);
  const SimFrame f = SimulateFrame(*world, 10);
  ASSERT_EQ(f.image.cols, 1226);
  ASSERT_EQ(f.image.rows, 370);
  const PinholeCamera cam = world->options.calibration.Camera(0);
  const Rigid3d map_from_cam =
      world->MapFromVeloAt(f.time) * world->options.calibration.cam0_from_velo.Inverse();
  // What does the ray through pixel (u, v) hit?  0 window/facade, 1 marking, 2 other, 3 sky.
  auto label = [&](double u, double v) {
    const Eigen::Vector3d d = (map_from_cam.RotationMatrix() * cam.Unproject({u, v})).normalized();
    const Hit hit = world->caster->Intersect(map_from_cam.translation(), d, 0.05, 400);
    if (!hit.valid()) return 3;
    const Surface s = ShadeSurface(world->scene, hit, map_from_cam.translation() + hit.t * d);
    if (s.marking) return 1;
    if (hit.face >= 0 && world->scene.mesh.faces[hit.face].material == Material::kFacade) return 0;
    return 2;
  };
  std::vector<cv::KeyPoint> kps;
  cv::ORB::create(1000)->detect(f.image, kps);
  int counts[4] = {0, 0, 0, 0};
  for (const auto& kp : kps) ++counts[label(kp.pt.x, kp.pt.y)];
  ASSERT_GT(kps.size(), 500u);
  EXPECT_GT(counts[0] + counts[1], static_cast<int>(kps.size()) / 2)
      << "facade " << counts[0] << " marking " << counts[1] << " other " << counts[2];
  auto lsd = cv::createLineSegmentDetector();
  std::vector<cv::Vec4f> lines;
  lsd->detect(f.image, lines);
  int long_lines = 0, on_facade = 0;
  for (const auto& l : lines) {
    if (std::hypot(l[2] - l[0], l[3] - l[1]) < 30) continue;
    ++long_lines;
    on_facade += label((l[0] + l[2]) / 2, (l[1] + l[3]) / 2) == 0 ? 1 : 0;
  }
  std::printf(
      "frame 10: ORB %zu keypoints: facade %d, lane marking %d, other %d, sky %d; "
      "LSD %d segments >= 30 px, %d on facades\n",
      kps.size(), counts[0], counts[1], counts[2], counts[3], long_lines, on_facade);
  EXPECT_GT(long_lines, 50);
  EXPECT_GT(on_facade, long_lines / 3);
}

// The road VP agrees with the GT pose and with the meeting point of the lane edge lines.
TEST(GroundTruthTest, RoadVpIsTheProjectionOfTheRoadDirection) {
  const auto world = SmallWorld(0.02, 0.02);
  const PinholeCamera cam = world->options.calibration.Camera(0);
  for (int64_t k : {3, 17, 29}) {
    const double t = world->ground_truth.timestamps[k];
    const SimFrame f = SimulateFrame(*world, k);
    ASSERT_FALSE(f.vps.empty());
    const GtVanishingPoint& road = f.vps.front();
    ASSERT_EQ(road.kind, VpKind::kRoad);
    ASSERT_TRUE(road.in_image);
    // Independent route: the GT pose (world frame) and a far point along the road direction.
    const Rigid3d map_from_cam = world->map_from_world * world->ground_truth.world_from_cam[k];
    const double s = DriveArcLength(world->drive, t);
    const RoadPoint rp = world->scene.route.At(s);
    const Eigen::Vector2d tan(std::cos(rp.heading), std::sin(rp.heading));
    const double slope = world->scene.terrain.Gradient(rp.position.x(), rp.position.y()).dot(tan);
    const Eigen::Vector3d far = Eigen::Vector3d(rp.position.x(), rp.position.y(), 0) +
                                1e7 * Eigen::Vector3d(tan.x(), tan.y(), slope);
    const Eigen::Vector2d uv = cam.Project(map_from_cam.Inverse() * far);
    EXPECT_LT((uv - road.uv).norm(), 0.5) << "frame " << k;
    // Lane edge lines (+-3.5 m) between 25 and 45 m ahead meet near the VP (the terrain bends
    // them slightly).
    auto edge = [&](double lat, double ahead) {
      const RoadPoint q = world->scene.route.At(s + ahead);
      const Eigen::Vector2d p =
          q.position + lat * Eigen::Vector2d(-std::sin(q.heading), std::cos(q.heading));
      const Eigen::Vector3d x(p.x(), p.y(), world->scene.terrain.Height(p.x(), p.y()));
      const Eigen::Vector2d pix = cam.Project(map_from_cam.Inverse() * x);
      return Eigen::Vector3d(pix.x(), pix.y(), 1.0);
    };
    const Eigen::Vector3d l1 = edge(3.5, 25).cross(edge(3.5, 45));
    const Eigen::Vector3d l2 = edge(-3.5, 25).cross(edge(-3.5, 45));
    const Eigen::Vector3d x = l1.cross(l2);
    EXPECT_LT((x.head<2>() / x.z() - road.uv).norm(), 12.0) << "frame " << k;
  }
}

}  // namespace
}  // namespace jvl::sim

namespace jvl::sim {
namespace {

// Moving forward at 10 m/s towards a wall 20 m ahead: without distortion the wall is at x = 20
// in every column; with it, a column fired tau seconds from the frame time measures 20 - 10 tau
// (tau = -0.1 az / 2 pi: the sweep runs clockwise and passes forward at the frame time).
TEST(LidarTest, MotionDistortionShiftsColumnsByTheMotion) {
  Scene scene;
  AddBox(scene.mesh, Eigen::Vector2d(20.5, 0), 0.0, 1.0, 100.0, -50, 50, 0, Material::kFacade,
         Material::kRoof, -1, 0.5f);
  for (auto& f : scene.mesh.faces) f.material = Material::kPole;  // Plain, no windows.
  const RayCaster caster(scene.mesh);
  LidarOptions opt;
  opt.range_noise = 0;
  opt.dropout = 0;
  opt.elevation_bias_deg = 0;
  const SweepPose sweep = [](double tau) {
    return Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(10 * tau, 0, 0));
  };
  for (bool distort : {false, true}) {
    opt.motion_distortion = distort;
    const PointCloud scan = SimulateScan(scene, caster, Rigid3d(), {}, opt, 1, &sweep);
    ASSERT_GT(scan.size(), 1000u);
    for (const auto& p : scan.points) {
      const double az = std::atan2(p.y(), p.x());
      const double expected = distort ? 20.0 + az / (2 * M_PI) : 20.0;
      EXPECT_NEAR(p.x(), expected, 2e-3) << "az " << az;
      if (std::abs(p.x() - expected) > 2e-3) break;
    }
  }
}

// With an elevation bias every return keeps its range and azimuth and lies that much lower,
// and lidar_odom's vertical correction (lidar::CorrectVerticalAngle) by the same angle gives the
// unbiased scan back.
TEST(LidarTest, ElevationBiasLowersEveryReturnAndTheCorrectionUndoesIt) {
  Scene scene;
  AddBox(scene.mesh, Eigen::Vector2d(20.5, 0), 0.0, 1.0, 100.0, -50, 50, 0, Material::kFacade,
         Material::kRoof, -1, 0.5f);
  for (auto& f : scene.mesh.faces) f.material = Material::kPole;
  const RayCaster caster(scene.mesh);
  LidarOptions opt;
  opt.dropout = 0;
  opt.elevation_bias_deg = 0;
  const PointCloud plain = SimulateScan(scene, caster, Rigid3d(), {}, opt, 3);
  opt.elevation_bias_deg = 0.22;
  const PointCloud biased = SimulateScan(scene, caster, Rigid3d(), {}, opt, 3);
  ASSERT_GT(plain.size(), 1000u);
  ASSERT_EQ(plain.size(), biased.size());
  std::vector<Eigen::Vector3d> corrected = biased.points;
  lidar::CorrectVerticalAngle(0.22 * M_PI / 180, &corrected);
  auto elevation = [](const Eigen::Vector3d& p) { return std::atan2(p.z(), p.head<2>().norm()); };
  double worst = 0;
  for (size_t i = 0; i < plain.size(); ++i) {
    const Eigen::Vector3d &u = plain.points[i], &b = biased.points[i];
    EXPECT_NEAR(b.norm(), u.norm(), 1e-4);
    EXPECT_NEAR(std::atan2(b.y(), b.x()), std::atan2(u.y(), u.x()), 1e-6);
    EXPECT_NEAR((elevation(u) - elevation(b)) * 180 / M_PI, 0.22, 1e-4);
    worst = std::max(worst, (corrected[i] - u).norm());
  }
  EXPECT_LT(worst, 1e-4);
  opt.elevation_bias_deg = 3;
  EXPECT_THROW(opt.Check(), std::exception);
}

// The calibration written is the rig's moved by the error asked for: that angle and distance,
// along directions drawn from the seed; none without an error.
TEST(SequenceTest, CalibrationErrorIsWrittenAsAsked) {
  SequenceOptions opt;
  const Rigid3d none = WrittenCalibrationError(opt);
  EXPECT_EQ(none.translation().norm(), 0);
  EXPECT_EQ(RotationAngle(none.rotation()), 0);
  opt.calib_error_deg = 0.5;
  opt.calib_error_m = 0.05;
  opt.seed = 7;
  const Rigid3d error = WrittenCalibrationError(opt);
  EXPECT_NEAR(RotationAngle(error.rotation()) * 180 / M_PI, 0.5, 1e-9);
  EXPECT_NEAR(error.translation().norm(), 0.05, 1e-12);
  const Calibration written = WrittenCalibration(opt);
  const Rigid3d expected = error * opt.calibration.cam0_from_velo;
  EXPECT_LT((written.cam0_from_velo.translation() - expected.translation()).norm(), 1e-12);
  EXPECT_LT(RotationAngle(written.cam0_from_velo.rotation().inverse() * expected.rotation()),
            1e-12);
  EXPECT_EQ(written.Camera(0).fx, opt.calibration.Camera(0).fx);  // Intrinsics untouched.
  // Deterministic per seed, another seed another direction.
  const Rigid3d again = WrittenCalibrationError(opt);
  EXPECT_EQ(again.translation(), error.translation());
  opt.seed = 8;
  EXPECT_GT((WrittenCalibrationError(opt).translation() - error.translation()).norm(), 1e-3);
  opt.calib_error_deg = -1;
  EXPECT_THROW(opt.Check(), std::exception);
}

}  // namespace
}  // namespace jvl::sim

namespace jvl::sim {
namespace {

// A tree crown is a volume of leaf clumps: horizontal rays aimed within half a radius of an
// isolated crown's centre stop at every depth inside it, and some pass through. With
// --foliage-density 0 the crown is one opaque surface: every ray stops at its shell.
TEST(SceneTest, CrownsAreVolumesThatRaysEnterAndPassThrough) {
  for (double density : {1.0, 0.0}) {
    SceneOptions so;
    so.scenario = Scenario::kHighway;
    so.seed = 3;
    so.foliage_density = density;
    so.hedge_coverage = 0;
    const Scene scene =
        BuildScene(Route(ScenarioRoute(so.scenario), Eigen::Vector2d::Zero(), 0.0), so);
    const Plant* tree = nullptr;
    for (const Plant& p : scene.plants) {
      bool alone = p.tree;
      for (const Plant& q : scene.plants)
        alone = alone && (&q == &p || (q.center - p.center).head<2>().norm() > 12);
      if (alone) {
        tree = &p;
        break;
      }
    }
    ASSERT_NE(tree, nullptr);
    const RayCaster caster(scene.mesh);
    const double r = tree->radius;
    int passed = 0, hits = 0, deep = 0;
    for (int k = 0; k < 400; ++k) {
      const double a = 2 * M_PI * k / 400, offset = r * (((k * 7) % 11) / 10.0 - 0.5);
      const Eigen::Vector3d d(-std::cos(a), -std::sin(a), 0);
      const Eigen::Vector3d o = tree->center + Eigen::Vector3d(0, 0, 0.3) - 10 * d +
                                offset * Eigen::Vector3d(-d.y(), d.x(), 0);
      const Hit hit = caster.Intersect(o, d, 0, 20);
      const bool in_crown = hit.valid() &&
                            scene.mesh.faces[hit.face].material == Material::kFoliage &&
                            (o + hit.t * d - tree->center).norm() < 1.5 * r;
      if (!in_crown) {
        ++passed;
        continue;
      }
      ++hits;
      if ((o + hit.t * d - tree->center).norm() < 0.6 * r) ++deep;
    }
    SCOPED_TRACE("foliage density " + std::to_string(density));
    if (density > 0) {
      EXPECT_GT(passed, 8);  // Chords of 4-5 m: exp(-0.5 x 4.5) ~ 10 % pass.
      EXPECT_LT(passed, 120);
      EXPECT_GT(deep, hits / 10);  // Stopped deep inside the crown.
    } else {
      EXPECT_EQ(passed, 0);
      EXPECT_EQ(deep, 0);  // The blob's shell is at 0.65-1.3 radii.
    }
  }
}

}  // namespace
}  // namespace jvl::sim
