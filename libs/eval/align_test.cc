#include "eval/align.h"

#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Geometry>
#include <random>

#include "core/check.h"

namespace jvl::eval {
namespace {

TEST(Umeyama, RecoversSimilarityExactly) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 10);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(5, -3, 2);
  const double s = 0.37;
  std::vector<Eigen::Vector3d> src, dst;
  for (int i = 0; i < 50; ++i) {
    src.emplace_back(n(rng), n(rng), n(rng));
    dst.push_back(s * r * src.back() + t);
  }
  const Similarity sim = Umeyama(src, dst, true);
  EXPECT_NEAR(sim.scale, s, 1e-12);
  EXPECT_TRUE(sim.rotation.isApprox(r, 1e-12));
  EXPECT_TRUE(sim.translation.isApprox(t, 1e-12));
  const Similarity rigid = Umeyama(src, dst, false);
  EXPECT_EQ(rigid.scale, 1.0);
  EXPECT_TRUE(rigid.rotation.isApprox(r, 1e-12));  // Rotation does not depend on the scale.
}

TEST(Umeyama, ReflectionIsNotReturned) {
  // Mirrored points: the best proper rotation has det +1.
  std::vector<Eigen::Vector3d> src = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  std::vector<Eigen::Vector3d> dst;
  for (const auto& p : src) dst.emplace_back(-p.x(), p.y(), p.z());
  EXPECT_NEAR(Umeyama(src, dst, true).rotation.determinant(), 1.0, 1e-12);
}

TEST(Umeyama, DegenerateInputThrows) {
  std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_THROW(Umeyama(two, two, true), Error);
  std::vector<Eigen::Vector3d> same(5, Eigen::Vector3d(1, 2, 3));
  EXPECT_THROW(Umeyama(same, same, true), Error);
}

TEST(Similarity, ApplyScalesTranslationThenMoves) {
  Similarity sim;
  sim.scale = 2;
  sim.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  sim.translation = Eigen::Vector3d(1, 0, 0);
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  pose(0, 3) = 1;
  const Eigen::Matrix4d out = sim.Apply(pose);
  EXPECT_TRUE((out.block<3, 1>(0, 3).isApprox(Eigen::Vector3d(1, 2, 0), 1e-15)));
  EXPECT_TRUE((out.topLeftCorner<3, 3>().isApprox(sim.rotation)));
  EXPECT_EQ(ParseAlignment("sim3"), Alignment::kSim3);
  EXPECT_THROW(ParseAlignment("7dof"), Error);
}

TEST(AlignTest, CollinearPositionsAreFlaggedIllConditioned) {
  std::vector<Eigen::Vector3d> line, spread;
  for (int i = 0; i < 50; ++i) {
    line.emplace_back(0.0, 0.0, 1.5 * i);
    spread.emplace_back(std::sin(0.1 * i) * 20, 0.5 * std::cos(0.3 * i), 1.5 * i);
  }
  EXPECT_TRUE(Umeyama(line, line, false).IllConditioned());
  EXPECT_LT(Umeyama(line, line, false).conditioning, 1e-9);
  EXPECT_FALSE(Umeyama(spread, spread, false).IllConditioned());
}

}  // namespace
}  // namespace jvl::eval
