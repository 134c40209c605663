#include "vision/guided_matching.h"

#include <gtest/gtest.h>

#include <random>

namespace jvl::vision {
namespace {

PinholeCamera KittiCamera() { return {718.856, 718.856, 607.1928, 185.2157, 1226, 370}; }

Descriptor RandomDescriptor(std::mt19937& rng) {
  Descriptor d;
  for (auto& b : d) b = static_cast<uint8_t>(rng() & 0xff);
  return d;
}

Descriptor FlipBits(Descriptor d, int n, std::mt19937& rng) {
  for (int i = 0; i < n; ++i) {
    const int bit = static_cast<int>(rng() % 256);
    d[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
  }
  return d;
}

// A synthetic scene: world points with descriptors, seen by frames whose keypoints are the noisy
// projections (slightly perturbed descriptors) plus "confusers": copies of the same descriptors at
// random places, which only the geometric constraints can tell apart.
struct Scene {
  std::vector<Eigen::Vector3d> points;
  std::vector<Descriptor> descriptors;
  std::mt19937 rng{42};
  explicit Scene(int n) {
    std::uniform_real_distribution<double> x(-15, 15), y(-3, 2), z(6, 60);
    for (int i = 0; i < n; ++i) {
      points.emplace_back(x(rng), y(rng), z(rng));
      descriptors.push_back(RandomDescriptor(rng));
    }
  }
  // truth[k] = point index of keypoint k, or -1 for confusers.
  OrbFeatures View(const PinholeCamera& cam, const Rigid3d& cam_from_world,
                   std::vector<int>* truth) {
    OrbFeatures f;
    std::normal_distribution<double> noise(0.0, 0.3);
    std::uniform_real_distribution<double> u(0, cam.width), v(0, cam.height);
    truth->clear();
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d p = cam_from_world * points[i];
      if (p.z() <= 0) continue;
      const Eigen::Vector2d uv = cam.Project(p) + Eigen::Vector2d(noise(rng), noise(rng));
      if (!cam.InImage(uv)) continue;
      f.keypoints.push_back(
          {uv.cast<float>(), static_cast<int>(i % 3), static_cast<float>(40 + noise(rng)), 30.f});
      f.descriptors.push_back(FlipBits(descriptors[i], 6, rng));
      truth->push_back(static_cast<int>(i));
      // A confuser with the same appearance somewhere else in the image.
      f.keypoints.push_back({Eigen::Vector2f(u(rng), v(rng)), static_cast<int>(i % 3), 40.f, 30.f});
      f.descriptors.push_back(FlipBits(descriptors[i], 6, rng));
      truth->push_back(-1);
    }
    return f;
  }
};

const std::vector<double> kScales = {1.0, 1.2, 1.44, 1.728, 2.0736, 2.48832, 2.985984, 3.5831808};

TEST(GuidedMatching, ProjectionWithKnownPoseFindsTheTrueKeypoints) {
  const PinholeCamera cam = KittiCamera();
  Scene scene(400);
  const Rigid3d cam_from_world =
      Rigid3d(ExpSO3(Eigen::Vector3d(0, 0.05, 0)), Eigen::Vector3d(0.2, 0, 3)).Inverse();
  std::vector<int> truth;
  const OrbFeatures frame = scene.View(cam, cam_from_world, &truth);
  std::vector<ProjectedPoint> projected;
  std::vector<int> point_of_row;
  for (size_t k = 0; k < truth.size(); ++k) {
    if (truth[k] < 0) continue;
    const int i = truth[k];
    const Eigen::Vector2d uv = cam.Project(cam_from_world * scene.points[i]);
    projected.push_back({uv, i % 3, scene.descriptors[i], 40.f});
    point_of_row.push_back(static_cast<int>(k));
  }
  ASSERT_GT(projected.size(), 150u);
  // Ten points whose reference orientation is off by 180 deg must be rejected.
  for (int r = 0; r < 10; ++r) projected[r].reference_angle = 220.f;
  const KeypointGrid grid(frame.keypoints, cam.width, cam.height);
  const std::vector<int> match =
      MatchByProjection(projected, frame, grid, kScales, ProjectionMatchOptions());
  int correct = 0, wrong = 0;
  for (size_t r = 0; r < match.size(); ++r) {
    if (match[r] < 0) continue;
    (match[r] == point_of_row[r] ? correct : wrong)++;
    EXPECT_GE(r, 10u) << "rotated reference accepted";
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GE(correct, static_cast<int>(0.95 * (projected.size() - 10)));
}

TEST(GuidedMatching, EpipolarMatchingWithKnownPosesPairsTheSamePoints) {
  const PinholeCamera cam = KittiCamera();
  Scene scene(500);
  const Rigid3d cam1_from_world = Rigid3d();
  const Rigid3d cam2_from_world =
      Rigid3d(ExpSO3(Eigen::Vector3d(0, -0.03, 0)), Eigen::Vector3d(0.1, 0, 2.0)).Inverse();
  std::vector<int> truth1, truth2;
  const OrbFeatures f1 = scene.View(cam, cam1_from_world, &truth1);
  const OrbFeatures f2 = scene.View(cam, cam2_from_world, &truth2);
  int common = 0;
  for (int t : truth1) {
    if (t >= 0 && std::find(truth2.begin(), truth2.end(), t) != truth2.end()) ++common;
  }
  const auto pairs = MatchEpipolar(cam, f1, cam1_from_world, {}, f2, cam2_from_world, {}, kScales,
                                   EpipolarMatchOptions());
  int correct = 0, wrong = 0;
  for (const auto& [i, j] : pairs) {
    (truth1[i] >= 0 && truth1[i] == truth2[j] ? correct : wrong)++;
  }
  EXPECT_LE(wrong, static_cast<int>(0.02 * pairs.size()) + 1);
  // Points near the epipole (image centre) and confusers on the epipolar line are lost.
  EXPECT_GE(correct, static_cast<int>(0.8 * common));

  // Keypoints marked used are never matched.
  std::vector<bool> used1(f1.size(), true);
  EXPECT_TRUE(MatchEpipolar(cam, f1, cam1_from_world, used1, f2, cam2_from_world, {}, kScales,
                            EpipolarMatchOptions())
                  .empty());
}

TEST(GuidedMatching, FundamentalMatrixSatisfiesEpipolarConstraint) {
  const PinholeCamera cam = KittiCamera();
  const Rigid3d c1 = Rigid3d(ExpSO3(Eigen::Vector3d(0.01, 0.1, 0)), Eigen::Vector3d(1, 0, 0));
  const Rigid3d c2 = Rigid3d(ExpSO3(Eigen::Vector3d(0, -0.2, 0.02)), Eigen::Vector3d(0, 0.3, -2));
  const Eigen::Matrix3d f21 = FundamentalFromPoses(cam, c1, c2);
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(1, 2, 10), Eigen::Vector3d(-3, 0, 25)}) {
    const Eigen::Vector3d u1 = cam.Project(c1 * x).homogeneous();
    const Eigen::Vector3d u2 = cam.Project(c2 * x).homogeneous();
    const Eigen::Vector3d line = f21 * u1;
    EXPECT_LT(std::abs(u2.dot(line)) / line.head<2>().norm(), 1e-6);  // Pixels.
  }
}

TEST(GuidedMatching, RotationHistogramKeepsTheDominantBins) {
  std::vector<float> diffs;
  for (int i = 0; i < 50; ++i) diffs.push_back(5.f + 0.1f * i);  // Bin 0.
  for (int i = 0; i < 20; ++i) diffs.push_back(-3.f);            // Wraps to bin 29.
  for (int i = 0; i < 10; ++i) diffs.push_back(13.f);            // Bin 1.
  diffs.push_back(180.f);                                        // Alone: rejected.
  diffs.push_back(95.f);
  const std::vector<bool> keep = RotationConsistent(diffs);
  for (int i = 0; i < 80; ++i) EXPECT_TRUE(keep[i]) << i;
  EXPECT_FALSE(keep[80]);
  EXPECT_FALSE(keep[81]);
}

TEST(GuidedMatching, GridWindowEqualsBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1226), v(0, 370);
  std::vector<OrbKeypoint> kps;
  for (int i = 0; i < 3000; ++i) kps.push_back({Eigen::Vector2f(u(rng), v(rng)), i % 8, 0.f, 0.f});
  const KeypointGrid grid(kps, 1226, 370);
  for (int q = 0; q < 50; ++q) {
    const Eigen::Vector2d c(u(rng), v(rng));
    const double r = 3.0 + q;
    std::vector<int> expected;
    for (int i = 0; i < 3000; ++i) {
      if (kps[i].octave >= 2 && kps[i].octave <= 3 && std::abs(kps[i].uv.x() - c.x()) <= r &&
          std::abs(kps[i].uv.y() - c.y()) <= r) {
        expected.push_back(i);
      }
    }
    EXPECT_EQ(grid.InWindow(c, r, 2, 3), expected);
  }
}

}  // namespace
}  // namespace jvl::vision
