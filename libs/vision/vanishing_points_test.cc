#include "vision/vanishing_points.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/check.h"
#include "geometry/rigid3.h"

namespace jvl {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

PinholeCamera KittiCamera() { return {707.0912, 707.0912, 601.8873, 183.1104, 1226, 370}; }

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * kRadToDeg;
}

// Segments of 3-D lines along `d` (random positions in front of the camera), projected and
// clipped to the image, endpoints perturbed by Gaussian pixel noise.
void AddSegments(const Eigen::Vector3d& d, int count, double noise_px, const PinholeCamera& cam,
                 std::mt19937_64& rng, std::vector<LineSegment>* out) {
  std::uniform_real_distribution<double> ux(-15, 15), uy(-4, 4), uz(4, 40), ul(2, 8);
  std::normal_distribution<double> noise(0, noise_px);
  int added = 0;
  for (int attempt = 0; added < count && attempt < 100 * count; ++attempt) {
    const Eigen::Vector3d a(ux(rng), uy(rng), uz(rng));
    const Eigen::Vector3d b = a + ul(rng) * d.normalized();
    if (a.z() < 1 || b.z() < 1) continue;
    LineSegment s{cam.Project(a), cam.Project(b)};
    if (!cam.InImage(s.p0) || !cam.InImage(s.p1) || s.length() < 30) continue;
    s.p0 += Eigen::Vector2d(noise(rng), noise(rng));
    s.p1 += Eigen::Vector2d(noise(rng), noise(rng));
    out->push_back(s);
    ++added;
  }
}

void AddOutliers(int count, const PinholeCamera& cam, std::mt19937_64& rng,
                 std::vector<LineSegment>* out) {
  std::uniform_real_distribution<double> u(0, cam.width), v(0, cam.height), a(0, 2 * M_PI),
      len(30, 120);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d p(u(rng), v(rng));
    const double t = a(rng);
    out->push_back({p, p + len(rng) * Eigen::Vector2d(std::cos(t), std::sin(t))});
  }
}

// Index of the found VP closest to d, or -1.
int Closest(const VpResult& r, const Eigen::Vector3d& d, double* angle_deg) {
  int best = -1;
  *angle_deg = 180;
  for (size_t k = 0; k < r.vps.size(); ++k) {
    const double a = AngleDeg(r.vps[k].direction, d);
    if (a < *angle_deg) {
      *angle_deg = a;
      best = static_cast<int>(k);
    }
  }
  return best;
}

TEST(VanishingPoints, FindsThreeOrthogonalVpsWithNoiseAndOutliers) {
  const PinholeCamera cam = KittiCamera();
  // A Manhattan frame yawed by 8 deg and pitched by 2 deg against the camera.
  const Eigen::Matrix3d r = ExpSO3(Eigen::Vector3d(2.0, 8.0, 0.0) / kRadToDeg).toRotationMatrix();
  const Eigen::Vector3d forward = r.col(2), lateral = r.col(0), vertical = r.col(1);
  for (uint64_t trial = 0; trial < 5; ++trial) {
    std::mt19937_64 rng(100 + trial);
    std::vector<LineSegment> segs;
    AddSegments(forward, 60, 0.5, cam, rng, &segs);
    AddSegments(vertical, 40, 0.5, cam, rng, &segs);
    AddSegments(lateral, 30, 0.5, cam, rng, &segs);
    AddOutliers(60, cam, rng, &segs);  // ~30 % outliers.
    const VpResult result = EstimateVanishingPoints(segs, cam, VpOptions{});
    ASSERT_EQ(result.vps.size(), 3u) << "trial " << trial;
    double angle = 0;
    const int f = Closest(result, forward, &angle);
    EXPECT_LT(angle, 0.3) << "trial " << trial;
    EXPECT_EQ(f, result.forward_index);
    EXPECT_TRUE(result.vps[f].is_forward);
    // 0.5 px endpoint noise on >= 30 px segments is up to ~1.4 deg of orientation noise, so a
    // few true segments fall outside the 1.5 deg threshold and a few outliers fit by chance.
    EXPECT_GE(result.vps[f].inliers, 50);
    EXPECT_LE(result.vps[f].inliers, 70);
    EXPECT_LT(result.vps[f].residual_deg, 0.8);
    EXPECT_GT(result.vps[f].score, 0);
    EXPECT_TRUE(result.vps[f].uv.allFinite());
    EXPECT_NEAR((result.vps[f].uv - cam.Project(forward)).norm(), 0, 5.0);
    EXPECT_LT(Closest(result, vertical, &angle) >= 0 ? angle : 99, 1.0);
    EXPECT_LT(Closest(result, lateral, &angle) >= 0 ? angle : 99, 1.0);
    int forward_flags = 0;
    for (const VanishingPoint& vp : result.vps) {
      EXPECT_NEAR(vp.direction.norm(), 1.0, 1e-12);
      EXPECT_GE(vp.direction.z(), 0.0);
      forward_flags += vp.is_forward ? 1 : 0;
    }
    EXPECT_EQ(forward_flags, 1);
  }
}

TEST(VanishingPoints, VpAtInfinityFromParallelImageLines) {
  const PinholeCamera cam = KittiCamera();
  // 3-D lines along the camera x axis project to parallel horizontal image lines.
  std::mt19937_64 rng(7);
  std::vector<LineSegment> exact, noisy;
  AddSegments(Eigen::Vector3d::UnitX(), 30, 0.0, cam, rng, &exact);
  const VpResult r0 = EstimateVanishingPoints(exact, cam, VpOptions{});
  ASSERT_GE(r0.vps.size(), 1u);
  EXPECT_LT(AngleDeg(r0.vps[0].direction, Eigen::Vector3d::UnitX()), 1e-6);
  EXPECT_LT(std::abs(r0.vps[0].direction.z()), kInfinityDz);
  EXPECT_TRUE(std::isnan(r0.vps[0].uv.x()) && std::isnan(r0.vps[0].uv.y()));
  EXPECT_FALSE(r0.vps[0].is_forward);  // 90 deg from the optical axis.
  EXPECT_EQ(r0.vps[0].inliers, 30);

  // Tilted 3-D lines (45 deg in the image), with noise: still a direction with z ~ 0.
  AddSegments(Eigen::Vector3d(1, 1, 0).normalized(), 30, 0.5, cam, rng, &noisy);
  const VpResult r1 = EstimateVanishingPoints(noisy, cam, VpOptions{});
  ASSERT_GE(r1.vps.size(), 1u);
  EXPECT_LT(AngleDeg(r1.vps[0].direction, Eigen::Vector3d(1, 1, 0)), 1.0);
  EXPECT_TRUE(r1.vps[0].direction.allFinite());
}

TEST(VanishingPoints, NoSegmentsGiveNoVps) {
  const PinholeCamera cam = KittiCamera();
  EXPECT_TRUE(EstimateVanishingPoints({}, cam, VpOptions{}).vps.empty());
  std::mt19937_64 rng(3);
  std::vector<LineSegment> few;
  AddSegments(Eigen::Vector3d::UnitZ(), 3, 0.0, cam, rng, &few);
  const VpResult r = EstimateVanishingPoints(few, cam, VpOptions{});  // Below min_inliers.
  EXPECT_TRUE(r.vps.empty());
  EXPECT_EQ(r.forward_index, -1);
  EXPECT_EQ(r.segment_vp, std::vector<int>(3, -1));

  const cv::Mat black(370, 1226, CV_8UC1, cv::Scalar(0));
  const VpResult image_result = DetectVanishingPoints(black, cam, VpDetectOptions{});
  EXPECT_TRUE(image_result.segments.empty());
  EXPECT_TRUE(image_result.vps.empty());
  EXPECT_TRUE(DetectVanishingPoints(cv::Mat(), cam, VpDetectOptions{}).vps.empty());
}

TEST(VanishingPoints, RenderedImageGivesTheDrawnVp) {
  const PinholeCamera cam = KittiCamera();
  const Eigen::Vector2d vp(640.0, 170.0);
  cv::Mat image(cam.height, cam.width, CV_8UC1, cv::Scalar(90));
  for (int k = 0; k < 16; ++k) {  // Thick bright rays from the bottom and top edges to the VP.
    const double x = -400 + 130.0 * k;
    const double y = k % 2 ? cam.height + 10.0 : -10.0;
    const Eigen::Vector2d from(x, y), to = from + 0.8 * (vp - from);
    cv::line(image, cv::Point2d(from.x(), from.y()), cv::Point2d(to.x(), to.y()), cv::Scalar(230),
             4, cv::LINE_AA);
  }
  for (LineDetector detector : {LineDetector::kFld, LineDetector::kLsd}) {
    if (detector == LineDetector::kFld && !FastLineDetectorAvailable()) continue;
    VpDetectOptions options;
    options.segments.detector = detector;
    const VpResult r = DetectVanishingPoints(image, cam, options);
    ASSERT_GE(r.vps.size(), 1u) << ToString(detector);
    ASSERT_GE(r.forward_index, 0) << ToString(detector);
    EXPECT_LT((r.vps[r.forward_index].uv - vp).norm(), 3.0) << ToString(detector);
  }
}

TEST(VanishingPoints, DeterministicAndResidualDefinition) {
  const PinholeCamera cam = KittiCamera();
  std::mt19937_64 rng(11);
  std::vector<LineSegment> segs;
  AddSegments(Eigen::Vector3d(0.1, 0, 1), 40, 1.0, cam, rng, &segs);
  AddOutliers(40, cam, rng, &segs);
  const VpResult a = EstimateVanishingPoints(segs, cam, VpOptions{});
  const VpResult b = EstimateVanishingPoints(segs, cam, VpOptions{});
  ASSERT_EQ(a.vps.size(), b.vps.size());
  for (size_t k = 0; k < a.vps.size(); ++k) {
    EXPECT_EQ(a.vps[k].direction, b.vps[k].direction);
    EXPECT_EQ(a.vps[k].score, b.vps[k].score);
  }
  EXPECT_EQ(a.segment_vp, b.segment_vp);
  // A segment pointing at the VP has zero residual; rotating it by 1 deg about its midpoint
  // gives 1 deg (near the principal point the dihedral angle equals the image angle).
  const Eigen::Vector3d d(0, 0, 1);
  const Eigen::Vector2d c(cam.cx, cam.cy);
  const LineSegment s{c + Eigen::Vector2d(5, 0), c + Eigen::Vector2d(65, 0)};
  EXPECT_NEAR(SegmentVpResidual(s, cam, d), 0.0, 1e-12);
  const double t = 1.0 / kRadToDeg;
  const Eigen::Vector2d mid = 0.5 * (s.p0 + s.p1), half(30 * std::cos(t), 30 * std::sin(t));
  const LineSegment rot{mid - half, mid + half};
  EXPECT_NEAR(SegmentVpResidual(rot, cam, d) * kRadToDeg, 1.0, 0.02);
}

TEST(VanishingPoints, OptionsAreChecked) {
  VpOptions o;
  o.inlier_threshold_deg = 0;
  EXPECT_THROW(o.Check(), Error);
  LineSegmentOptions s;
  s.scale = 0;
  EXPECT_THROW(s.Check(), Error);
  EXPECT_THROW(ParseLineDetector("hough"), Error);
  EXPECT_EQ(ParseLineDetector("lsd"), LineDetector::kLsd);
}

}  // namespace
}  // namespace jvl
