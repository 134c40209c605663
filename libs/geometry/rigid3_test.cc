#include "geometry/rigid3.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace jvl {
namespace {

Rigid3d RandomPose(std::mt19937& rng, double max_angle = 3.0) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Vector3d axis(u(rng), u(rng), u(rng));
  axis.normalize();
  const double angle = max_angle * std::abs(u(rng));
  return Rigid3d(ExpSO3(angle * axis), Eigen::Vector3d(10 * u(rng), 10 * u(rng), 10 * u(rng)));
}

void ExpectNear(const Rigid3d& a, const Rigid3d& b, double tol) {
  EXPECT_LT(RotationAngle(a.rotation().conjugate() * b.rotation()), tol);
  EXPECT_LT((a.translation() - b.translation()).norm(), tol);
}

TEST(Rigid3Test, ComposeAndInverse) {
  std::mt19937 rng(1);
  for (int i = 0; i < 100; ++i) {
    const Rigid3d b_from_a = RandomPose(rng), c_from_b = RandomPose(rng);
    const Eigen::Vector3d p(1, -2, 3);
    EXPECT_LT(((c_from_b * b_from_a) * p - c_from_b * (b_from_a * p)).norm(), 1e-9);
    ExpectNear(b_from_a * b_from_a.Inverse(), Rigid3d(), 1e-12);
    EXPECT_LT((b_from_a.Matrix4() * b_from_a.Inverse().Matrix4() -
               Eigen::Matrix4d::Identity()).norm(), 1e-12);
  }
}

TEST(Rigid3Test, ArrayLayoutIsXyzwThenTranslation) {
  const Rigid3d t(Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5), Eigen::Vector3d(1, 2, 3));
  const auto a = t.ToArray();
  EXPECT_DOUBLE_EQ(a[3], 0.5);  // qw
  EXPECT_DOUBLE_EQ(a[4], 1.0);
  ExpectNear(Rigid3d::FromArray(a.data()), t, 1e-15);
}

TEST(Rigid3Test, FromMatrixProjectsOntoSO3) {
  Eigen::Matrix<double, 3, 4> m;
  m << 1, 1e-7, 0, 1, 0, 1, 0, 2, 0, 0, 1.0000001, 3;
  const Rigid3d t = Rigid3d::FromMatrix(m);
  EXPECT_NEAR(t.RotationMatrix().determinant(), 1.0, 1e-12);
  EXPECT_NEAR(t.translation().z(), 3.0, 1e-15);
}

TEST(Rigid3Test, ExpLogSO3RoundTripIncludingSmallAndNearPi) {
  for (double angle : {0.0, 1e-12, 1e-6, 0.3, 2.0, M_PI - 1e-6}) {
    const Eigen::Vector3d omega = angle * Eigen::Vector3d(1, 2, -2).normalized();
    EXPECT_LT((LogSO3(ExpSO3(omega)) - omega).norm(), 1e-9) << angle;
  }
  // Matches Eigen's AngleAxis.
  const Eigen::Vector3d w(0.1, -0.4, 0.7);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(w.norm(), w.normalized()));
  EXPECT_LT(RotationAngle(q.conjugate() * ExpSO3(w)), 1e-12);
}

TEST(Rigid3Test, ExpLogSE3RoundTrip) {
  std::mt19937 rng(2);
  for (int i = 0; i < 100; ++i) {
    const Rigid3d t = RandomPose(rng);
    ExpectNear(ExpSE3(LogSE3(t)), t, 1e-9);
  }
  Vector6d xi = Vector6d::Zero();
  xi.head<3>() << 1, 2, 3;  // Pure translation.
  EXPECT_LT((ExpSE3(xi).translation() - Eigen::Vector3d(1, 2, 3)).norm(), 1e-15);
}

TEST(Rigid3Test, InterpolateEndpointsAndMidpoint) {
  const Rigid3d a(ExpSO3(Eigen::Vector3d(0, 0.2, 0)), Eigen::Vector3d(0, 0, 0));
  const Rigid3d b(ExpSO3(Eigen::Vector3d(0, 0.6, 0)), Eigen::Vector3d(4, 0, 2));
  ExpectNear(Interpolate(a, b, 0), a, 1e-12);
  ExpectNear(Interpolate(a, b, 1), b, 1e-9);
  const Rigid3d mid = InterpolateDecoupled(a, b, 0.5);
  EXPECT_NEAR(LogSO3(mid.rotation()).y(), 0.4, 1e-12);
  EXPECT_LT((mid.translation() - Eigen::Vector3d(2, 0, 1)).norm(), 1e-12);
  EXPECT_NEAR(LogSO3(Interpolate(a, b, 0.5).rotation()).y(), 0.4, 1e-12);
}

}  // namespace
}  // namespace jvl
