#include "fidelity/edge_alignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/check.h"
#include "geometry/rigid3.h"
#include "io/schema_check.h"

namespace jvl::fidelity {
namespace {

constexpr double kDeg = M_PI / 180.0;

struct Box {
  Eigen::Vector3d lo, hi;  // LiDAR frame: x forward, y left, z up.
};

// A street-like scene in the LiDAR frame: the road 1.73 m below the sensor, a facade across the
// street 40 m ahead, a long facade along the left side (seen at grazing angles), and boxes and
// poles in front of them.
struct Scene {
  std::vector<Box> boxes = {
      {{15, 2, -1.73}, {16, 4, 1.5}},
      {{20, -6, -1.73}, {21, -3, 3}},
      {{12, -2, -1.73}, {13, -1, 0.5}},
      {{25, 5, -1.73}, {25.3, 5.3, 6}},
      {{30, -9, -1.73}, {30.4, -8.6, 7}},
      {{18, 5.5, 0.5}, {19, 7, 2.5}},
      {{35, -3, -1.73}, {36, 1, 2}},
      // Parked cars along both kerbs and lower blocks before the far facade: horizontal
      // outlines against what lies behind them.
      {{10, -5, -1.73}, {14.5, -3.2, -0.3}},
      {{22, 3.2, -1.73}, {26.5, 5, -0.2}},
      {{17, -5.2, -1.73}, {21.5, -3.4, -0.25}},
      {{28, 2, -1.73}, {32, 4, 0}},
      {{31, -20, -1.73}, {33, -10, 5}},
      {{31, 8, -1.73}, {33, 20, 7}},
      {{33, 1.5, -1.73}, {34, 7, 3.5}},
      // Low walls on both sides and sign boards over the street (top and bottom outlines).
      {{26, -12, -1.73}, {27, -6, 1.0}},
      {{26, 6, -1.73}, {27, 12, 1.2}},
      {{22, -1, 1.5}, {22.5, 1, 2.0}},
      {{28, -8, 2.5}, {28.5, -4, 3.2}},
      {{28, 4, 2.8}, {28.5, 8, 3.4}},
      {{24, -14, 4}, {24.5, -10, 4.8}},
      {{24, 10, 3.6}, {24.5, 14, 4.4}},
  };
  double sensor_x = 0;       // The sensor's position along the street (m).
  double left_facade_y = 8;  // How far left of the sensor the left facade stands (m).
  // Returns the range along unit direction d (infinity: nothing hit) and the intensity there.
  double Cast(const Eigen::Vector3d& d, int* intensity) const {
    const Eigen::Vector3d shift(sensor_x, 0, 0);
    double best = std::numeric_limits<double>::infinity();
    *intensity = 235;  // sky
    auto take = [&](double t, int value) {
      if (t > 0 && t < best) {
        best = t;
        *intensity = value;
      }
    };
    for (const Box& b : boxes) {
      double t0 = 0, t1 = std::numeric_limits<double>::infinity();
      bool hit = true;
      for (int a = 0; a < 3 && hit; ++a) {
        if (std::abs(d[a]) < 1e-12) {
          hit = shift[a] >= b.lo[a] && shift[a] <= b.hi[a];
          continue;
        }
        double ta = (b.lo - shift)[a] / d[a], tb = (b.hi - shift)[a] / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        hit = t0 <= t1;
      }
      if (hit) take(t0, 200);
    }
    if (d.x() > 0) {  // The facade across the street, 40 m ahead, up to 15 m high.
      const double t = (40 - sensor_x) / d.x();
      const Eigen::Vector3d p = t * d;
      if (std::abs(p.y()) < 40 && p.z() < 15) take(t, 110);
    }
    if (d.y() > 0) {  // The left facade along the street, from 5 to 38 m.
      const double t = left_facade_y / d.y();
      const Eigen::Vector3d p = t * d + shift;
      if (p.x() > 5 && p.x() < 38 && p.z() < 12) take(t, 150);
    }
    if (d.z() < 0) take(-1.73 / d.z(), 60);  // The road.
    return best;
  }
};

// KITTI-like rig: camera 0 at the LiDAR's origin, looking along its x axis.
Calibration TrueCalibration() {
  Calibration c;
  c.P[0] << 718, 0, 607, 0, 0, 718, 185, 0, 0, 0, 1, 0;
  for (int i = 1; i < 4; ++i) c.P[i] = c.P[0];
  Eigen::Matrix3d r;
  r << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  c.cam0_from_velo = Rigid3d(r, Eigen::Vector3d::Zero());
  c.image_width = 1241;
  c.image_height = 376;
  return c;
}

// A spinning LiDAR's returns over the camera's field of view: 64 rings from -24.8 to +1.7 deg
// (an HDL-64), 0.17 deg apart in azimuth.
PointCloud ScanOf(const Scene& scene) {
  PointCloud scan;
  for (int ring = 0; ring < 64; ++ring) {
    const double elevation = (-24.8 + ring * 0.42) * kDeg;
    for (double azimuth = -60; azimuth <= 60; azimuth += 0.17) {
      const Eigen::Vector3d d(std::cos(elevation) * std::cos(azimuth * kDeg),
                              std::cos(elevation) * std::sin(azimuth * kDeg), std::sin(elevation));
      int intensity = 0;
      const double r = scene.Cast(d, &intensity);
      if (std::isfinite(r) && r < 120) scan.points.push_back(r * d);
    }
  }
  return scan;
}

cv::Mat ImageOf(const Scene& scene, const Calibration& calibration) {
  const PinholeCamera cam = calibration.Camera(0);
  const Eigen::Matrix3d velo_from_cam0 = calibration.cam0_from_velo.RotationMatrix().transpose();
  cv::Mat image(calibration.image_height, calibration.image_width, CV_8U);
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      const Eigen::Vector3d d = (velo_from_cam0 * cam.Unproject({u, v})).normalized();
      int intensity = 0;
      scene.Cast(d, &intensity);
      image.at<uint8_t>(v, u) = static_cast<uint8_t>(intensity);
    }
  }
  return image;
}

double DistanceToBox(const Box& b, const Eigen::Vector3d& p) {
  const Eigen::Vector3d outside = (b.lo - p).cwiseMax(p - b.hi).cwiseMax(0.0);
  return outside.norm();
}

TEST(EdgeAlignment, DepthEdgesOutlineTheObjectsAndNotGrazingSurfaces) {
  const Scene scene;
  const EdgeAlignmentOptions o;
  const DepthEdges edges = FindDepthEdges(ScanOf(scene), o);
  ASSERT_GT(edges.points.size(), 200u);
  int on_box = 0, on_grazing_facade = 0, on_road = 0;
  for (const Eigen::Vector3d& p : edges.points) {
    double nearest = 1e9;
    for (const Box& b : scene.boxes) nearest = std::min(nearest, DistanceToBox(b, p));
    // On a box, or at an end of a facade (their vertical outlines).
    for (const Eigen::Vector2d& end : {Eigen::Vector2d(5, 8), Eigen::Vector2d(38, 8),
                                       Eigen::Vector2d(40, 40), Eigen::Vector2d(40, -40)})
      nearest = std::min(nearest, (p.head<2>() - end).norm());
    on_box += nearest < 0.3 ? 1 : 0;
    // Inside the left facade's extent, away from its far end and from the boxes before it.
    on_grazing_facade += std::abs(p.y() - 8) < 0.2 && p.x() > 6 && p.x() < 35 ? 1 : 0;
    on_road += p.z() < -1.6 && nearest > 0.5 ? 1 : 0;
  }
  // The returns at an object's outline (moved half way towards the return behind it) ...
  EXPECT_EQ(on_box, static_cast<int>(edges.points.size()));
  // ... and none on the facade seen at a grazing angle or on the road between its rings.
  EXPECT_EQ(on_grazing_facade, 0);
  EXPECT_LE(on_road, 0.02 * static_cast<double>(edges.points.size()));
}

// A facade 3 m to the left seen at 4-30 deg: the range between neighbouring returns grows by up
// to a metre, but evenly (a gradient, not an edge): only the facade's ends are outlines.
TEST(EdgeAlignment, AFacadeSeenAtAGrazingAngleHasNoOutlineButItsEnds) {
  Scene scene;
  scene.boxes.clear();
  scene.left_facade_y = 3;
  const DepthEdges edges = FindDepthEdges(ScanOf(scene), EdgeAlignmentOptions());
  int inside = 0;
  for (const Eigen::Vector3d& p : edges.points)
    inside += std::abs(p.y() - 3) < 0.2 && p.x() > 6 && p.x() < 37 ? 1 : 0;
  EXPECT_EQ(inside, 0);
  EXPECT_GT(edges.points.size(), 10u);  // The facade's ends.
}

TEST(EdgeAlignment, EdgeFieldPeaksOnTheEdge) {
  cv::Mat step(60, 200, CV_8U, cv::Scalar(50));
  step.colRange(100, 200).setTo(200);
  const EdgeFields fields = EdgeField(step, EdgeAlignmentOptions());
  const cv::Mat& field = fields.across_u;
  // No horizontal edge: the field across horizontal edges is flat.
  EXPECT_LE(cv::norm(fields.across_v, cv::NORM_INF), 1e-3);
  ASSERT_EQ(field.type(), CV_32F);
  int best = 0;
  for (int u = 1; u < field.cols; ++u)
    if (field.at<float>(30, u) > field.at<float>(30, best)) best = u;
  EXPECT_NEAR(best, 99.5, 1.0);
  // Less its local mean: far from the edge the field is not positive.
  EXPECT_LE(field.at<float>(30, 20), 1e-3);
  EXPECT_GT(field.at<float>(30, best), 0.3);
}

// The rotation written into the calibration is found and undone in yaw, which the many
// vertical outlines of every frame hold. Pitch and roll rest on the few horizontal outlines
// seen edge-on, which a 64-ring LiDAR places only to within half a ring spacing (0.21 deg): a
// small static scene does not average that out, a drive's many objects at changing distances
// do (tests/pipelines/calib_check.sh checks all three axes on a simulated drive).
TEST(EdgeAlignment, FindsTheYawErrorOfTheCalibration) {
  const Calibration truth = TrueCalibration();
  EdgeAlignmentOptions o;
  o.bootstrap = 0;
  o.min_depth_m = 5;
  // Frames along the street, 1.1 m apart.
  std::vector<Scene> views(10);
  for (size_t k = 0; k < views.size(); ++k) views[k].sensor_x = 1.1 * static_cast<double>(k);
  std::vector<PointCloud> scans;
  std::vector<cv::Mat> images;
  for (const Scene& view : views) {
    scans.push_back(ScanOf(view));
    images.push_back(ImageOf(view, truth));
  }
  for (const Eigen::Vector3d& error_deg :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.25, -0.35, 0.2),
        Eigen::Vector3d(-0.1, 0.5, 0)}) {
    Calibration written = truth;
    written.cam0_from_velo =
        Rigid3d(ExpSO3(error_deg * kDeg), Eigen::Vector3d::Zero()) * truth.cam0_from_velo;
    std::vector<AlignmentFrame> frames;
    for (size_t k = 0; k < views.size(); ++k)
      frames.push_back(MakeAlignmentFrame(scans[k], images[k], written, 0, o));
    const EdgeAlignmentResult r =
        AlignEdges(frames, written.Camera(0), written.CameraOffset(0), o, 2);
    SCOPED_TRACE(testing::Message() << "error " << error_deg.transpose());
    EXPECT_NEAR(r.correction_deg.y(), -error_deg.y(), 0.04);
    EXPECT_GT(r.edge_points, 500);
    // The corrected calibration's optical axis points where the true one does, within what
    // pitch leaves open.
    const Calibration fixed = CorrectedCalibration(written, r.correction_deg);
    const Eigen::Vector3d axis_fixed =
        fixed.cam0_from_velo.rotation().inverse() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d axis_true =
        truth.cam0_from_velo.rotation().inverse() * Eigen::Vector3d::UnitZ();
    // Yaw of the optical axis in the LiDAR frame (about its z axis).
    const double yaw_off =
        std::atan2(axis_fixed.y(), axis_fixed.x()) - std::atan2(axis_true.y(), axis_true.x());
    EXPECT_LT(std::abs(yaw_off) / kDeg, 0.05);
  }
}

// Same frames and options, one or two threads: the same result to the last bit.
TEST(EdgeAlignment, ResultDoesNotDependOnTheThreadCount) {
  const Calibration truth = TrueCalibration();
  EdgeAlignmentOptions o;
  o.bootstrap = 30;
  o.min_depth_m = 5;
  o.search_deg = 0.3;
  std::vector<AlignmentFrame> frames;
  for (const double x : {0.0, 1.5, 3.0}) {
    Scene view;
    view.sensor_x = x;
    frames.push_back(MakeAlignmentFrame(ScanOf(view), ImageOf(view, truth), truth, 0, o));
  }
  const EdgeAlignmentResult one =
      AlignEdges(frames, truth.Camera(0), Eigen::Vector3d::Zero(), o, 1);
  const EdgeAlignmentResult two =
      AlignEdges(frames, truth.Camera(0), Eigen::Vector3d::Zero(), o, 2);
  EXPECT_EQ(EdgeAlignmentJson(one, o).dump(), EdgeAlignmentJson(two, o).dump());
}

TEST(EdgeAlignment, ArtifactMatchesItsSchema) {
  EdgeAlignmentResult r;
  r.correction_deg = Eigen::Vector3d(0.1, -0.2, 0.05);
  r.frames = 2;
  r.edge_points = 120;
  r.frame_score_calibration = {1.0, 2.0};
  r.frame_score_corrected = {1.5, 1.9};
  nlohmann::json doc = EdgeAlignmentJson(r, EdgeAlignmentOptions());
  EXPECT_EQ(doc["frames_better"], 1);
  EXPECT_DOUBLE_EQ(doc["calibration_error_deg"]["yaw_y"].get<double>(), 0.2);
  doc["schema"] = "calib_check";
  doc["schema_version"] = 1;
  doc["provenance"] = nlohmann::json::object();
  doc["frames"] = {4, 5};
  doc["camera"] = 0;
  doc["vertical_correction_deg"] = 0.0;
  const std::string schema = std::string(JVL_SOURCE_DIR) + "/schemas/calib_check.schema.json";
  EXPECT_TRUE(io::CheckJsonAgainstSchema(doc, schema).empty());
  doc["correction_deg"].erase("roll_z");
  EXPECT_FALSE(io::CheckJsonAgainstSchema(doc, schema).empty());
}

TEST(EdgeAlignment, OptionsAreChecked) {
  EdgeAlignmentOptions o;
  o.min_depth_m = 50;
  o.max_depth_m = 40;
  EXPECT_THROW(o.Check(), Error);
  o = EdgeAlignmentOptions();
  o.fine_step_deg = 0.5;
  EXPECT_THROW(o.Check(), Error);
  o = EdgeAlignmentOptions();
  o.edge_decay = 1;
  EXPECT_THROW(o.Check(), Error);
  EXPECT_THROW(AlignEdges({}, PinholeCamera(), Eigen::Vector3d::Zero(), EdgeAlignmentOptions(), 1),
               Error);
}

}  // namespace
}  // namespace jvl::fidelity
