#include "optim/analytic_costs.h"

#include <gtest/gtest.h>

#include <array>
#include <memory>

#include "optim/cost_functions.h"
#include "optim/test_util.h"

namespace jvl::optim {
namespace {

using testing::CheckGradient;
using testing::KittiLikeCamera;
using testing::LocalJacobianError;
using testing::RandomPose;

// Residuals and ambient Jacobians of two cost functions must agree.
void ExpectSameEvaluation(const ceres::CostFunction& a, const ceres::CostFunction& b,
                          std::vector<double*> params) {
  ASSERT_EQ(a.num_residuals(), b.num_residuals());
  ASSERT_EQ(a.parameter_block_sizes(), b.parameter_block_sizes());
  const int m = a.num_residuals();
  std::vector<double> ra(m), rb(m);
  std::vector<std::vector<double>> ja, jb;
  std::vector<double*> pa, pb;
  for (int32_t size : a.parameter_block_sizes()) {
    ja.emplace_back(static_cast<size_t>(size * m));
    jb.emplace_back(static_cast<size_t>(size * m));
  }
  for (size_t i = 0; i < ja.size(); ++i) {
    pa.push_back(ja[i].data());
    pb.push_back(jb[i].data());
  }
  ASSERT_TRUE(a.Evaluate(params.data(), ra.data(), pa.data()));
  ASSERT_TRUE(b.Evaluate(params.data(), rb.data(), pb.data()));
  for (int i = 0; i < m; ++i) EXPECT_NEAR(ra[i], rb[i], 1e-9 * (1 + std::abs(rb[i])));
  for (size_t k = 0; k < ja.size(); ++k) {
    for (size_t i = 0; i < ja[k].size(); ++i) {
      EXPECT_NEAR(ja[k][i], jb[k][i], 1e-8 * (1 + std::abs(jb[k][i])))
          << "block " << k << " entry " << i;
    }
  }
}

TEST(RotateJacobian, MatchesFiniteDifferences) {
  std::mt19937 rng(5);
  const Eigen::Vector3d v(0.3, -1.2, 2.0);
  for (int trial = 0; trial < 5; ++trial) {
    const PoseBlock block = ToPoseBlock(RandomPose(rng, 2.0, 1.0));
    const Eigen::Matrix<double, 3, 4> j = RotateJacobian(block.data(), v);
    const Eigen::Matrix<double, 3, 4> jt = InverseRotateJacobian(block.data(), v);
    for (int k = 0; k < 4; ++k) {
      const double h = 1e-6;
      std::array<double, 4> qp = {block[0], block[1], block[2], block[3]};
      std::array<double, 4> qm = qp;
      qp[k] += h;
      qm[k] -= h;
      // Unnormalised quaternion product, the same polynomial as Eigen's q * v.
      const Eigen::Map<const Eigen::Quaterniond> a(qp.data()), b(qm.data());
      const Eigen::Vector3d num = (a * v - b * v) / (2 * h);
      const Eigen::Vector3d num_t = (a.conjugate() * v - b.conjugate() * v) / (2 * h);
      EXPECT_LT((j.col(k) - num).norm(), 1e-7);
      EXPECT_LT((jt.col(k) - num_t).norm(), 1e-7);
    }
  }
}

TEST(VisualReprojectionAnalyticCost, MatchesAutodiffAndNumericAndFailsBehindTheCamera) {
  std::mt19937 rng(5);
  const PinholeCamera camera = KittiLikeCamera();
  for (int trial = 0; trial < 10; ++trial) {
    const Rigid3d world_from_cam = RandomPose(rng, 0.5, 10.0);
    // A point 4-40 m in front of the camera, observed 0-3 px off its projection.
    const Eigen::Vector3d x_c(0.3 * trial - 1.5, 0.5, 4.0 + 4.0 * trial);
    std::array<double, 3> point;
    Eigen::Map<Eigen::Vector3d>(point.data()) = world_from_cam * x_c;
    const Eigen::Vector2d uv = camera.Project(x_c) + Eigen::Vector2d(0.3 * trial, -0.2 * trial);
    PoseBlock pose = ToPoseBlock(world_from_cam);
    VisualReprojectionAnalyticCost analytic(camera, uv, 1.0 / 1.44);
    std::unique_ptr<ceres::CostFunction> autodiff(
        VisualReprojectionCost::Create(camera, uv, 1.0 / 1.44));
    ExpectSameEvaluation(analytic, *autodiff, {pose.data(), point.data()});
    EXPECT_LT(LocalJacobianError(analytic, {true, false}, {pose.data(), point.data()}), 1e-5);
  }
  const Rigid3d world_from_cam = RandomPose(rng, 0.5, 10.0);
  std::array<double, 3> behind;
  Eigen::Map<Eigen::Vector3d>(behind.data()) = world_from_cam * Eigen::Vector3d(0, 0, -5);
  PoseBlock pose = ToPoseBlock(world_from_cam);
  const double* params[2] = {pose.data(), behind.data()};
  double r[2];
  EXPECT_FALSE(
      VisualReprojectionAnalyticCost(camera, {600, 180}, 1.0).Evaluate(params, r, nullptr));
}

// A camera beside the pose's frame (KITTI's camera 2, 6 cm left of camera 0): the residual is
// that of the camera placed at the offset, and the Jacobians still match.
TEST(VisualReprojectionAnalyticCost, CameraOffsetMovesTheObservingCamera) {
  std::mt19937 rng(7);
  const PinholeCamera camera = KittiLikeCamera();
  const Eigen::Vector3d offset(0.061, -0.0003, 0.0062);
  const Rigid3d camera_from_cam0(Eigen::Quaterniond::Identity(), offset);
  for (int trial = 0; trial < 10; ++trial) {
    const Rigid3d world_from_cam0 = RandomPose(rng, 0.5, 10.0);
    const Eigen::Vector3d x_c0(0.3 * trial - 1.5, 0.5, 4.0 + 4.0 * trial);
    std::array<double, 3> point;
    Eigen::Map<Eigen::Vector3d>(point.data()) = world_from_cam0 * x_c0;
    const Eigen::Vector2d uv = camera.Project(x_c0 + offset) + Eigen::Vector2d(0.2, -0.1 * trial);
    PoseBlock pose = ToPoseBlock(world_from_cam0);
    VisualReprojectionAnalyticCost analytic(camera, uv, 1.0, offset);
    std::unique_ptr<ceres::CostFunction> autodiff(
        VisualReprojectionCost::Create(camera, uv, 1.0, offset));
    ExpectSameEvaluation(analytic, *autodiff, {pose.data(), point.data()});
    EXPECT_LT(LocalJacobianError(analytic, {true, false}, {pose.data(), point.data()}), 1e-5);
    // The same residual as camera 2's own pose without an offset.
    PoseBlock camera_pose = ToPoseBlock(world_from_cam0 * camera_from_cam0.Inverse());
    VisualReprojectionAnalyticCost plain(camera, uv, 1.0);
    const double* with[2] = {pose.data(), point.data()};
    const double* without[2] = {camera_pose.data(), point.data()};
    double r_with[2], r_without[2];
    ASSERT_TRUE(analytic.Evaluate(with, r_with, nullptr));
    ASSERT_TRUE(plain.Evaluate(without, r_without, nullptr));
    EXPECT_NEAR(r_with[0], r_without[0], 1e-9);
    EXPECT_NEAR(r_with[1], r_without[1], 1e-9);
    EXPECT_NEAR(r_with[0], 0.2, 1e-9);  // s (uv - projection)
  }
}

TEST(PointToImlsAnalyticCost, MatchesAutodiffAndNumeric) {
  std::mt19937 rng(6);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Vector3d p_x(rng() % 20 - 10.0, 1.0, 15.0);
    const Eigen::Vector3d c_p_y(2.0, 1.5, 9.0);
    const Eigen::Vector3d normal = Eigen::Vector3d(0.3, -0.8, 0.1 * trial).normalized();
    PoseBlock pose_n = ToPoseBlock(RandomPose(rng, 0.5, 10.0));
    PoseBlock pose_c = ToPoseBlock(RandomPose(rng, 0.5, 10.0));
    PointToImlsAnalyticCost analytic(p_x, c_p_y, normal, 7.0);
    std::unique_ptr<ceres::CostFunction> autodiff(PointToImlsCost::Create(p_x, c_p_y, normal, 7.0));
    ExpectSameEvaluation(analytic, *autodiff, {pose_n.data(), pose_c.data()});
    std::string log;
    EXPECT_LT(CheckGradient(analytic, {true, true}, {pose_n.data(), pose_c.data()}, &log), 1e-6)
        << log;
    EXPECT_LT(LocalJacobianError(analytic, {true, true}, {pose_n.data(), pose_c.data()}), 1e-5);
  }
}

// e_D's whitening per image axis (u, v), different on purpose so a swapped axis shows.
const Eigen::Vector2d kSqrtInfo(0.5, 0.8);

TEST(DirectionProjectionAnalyticCost, MatchesAutodiffAndNumericIncludingGuards) {
  std::mt19937 rng(7);
  const PinholeCamera camera = KittiLikeCamera();
  const std::vector<Eigen::Vector3d> directions = {
      {0.05, 0.01, 1.0}, {-0.3, 0.1, 0.9}, {0.1, 0.0, -1.0} /* flipped */, {1.0, 0.0, 0.01}
      /* clamped */};
  for (const Eigen::Vector3d& d_cam : directions) {
    const Rigid3d world_from_cam = RandomPose(rng, 0.4, 5.0);
    const Eigen::Vector3d d_w = world_from_cam.rotation() * d_cam.normalized();
    const Eigen::Vector2d vp(650.0, 170.0);
    PoseBlock pose = ToPoseBlock(world_from_cam);
    DirectionProjectionAnalyticCost analytic(camera, vp, d_w, kSqrtInfo, 0.05);
    std::unique_ptr<ceres::CostFunction> autodiff(
        DirectionProjectionCost::Create(camera, vp, d_w, kSqrtInfo, 0.05));
    ExpectSameEvaluation(analytic, *autodiff, {pose.data()});
    EXPECT_LT(LocalJacobianError(analytic, {true}, {pose.data()}), 1e-5) << d_cam.transpose();
    // With the clamp active (residual ~1e4 px, true derivative ~1e2) ceres::GradientChecker's
    // ambient-space numeric Jacobian disagrees while the on-manifold differences above agree, so
    // GradientChecker runs on the unclamped cases only.
    if (d_cam.z() > 0.05 || d_cam.z() < -0.05) {
      std::string log;
      EXPECT_LT(CheckGradient(analytic, {true}, {pose.data()}, &log), 1e-5) << log;
    }
  }
}

// The free form (d_w as a parameter block) gives the fixed form's residual and pose Jacobian,
// and its direction Jacobian matches numeric differences (plain 3-vector block: the sphere
// manifold's PlusJacobian is applied by Ceres).
TEST(DirectionProjectionFreeCost, MatchesTheFixedFormAndNumeric) {
  std::mt19937 rng(8);
  const PinholeCamera camera = KittiLikeCamera();
  for (const Eigen::Vector3d& d_cam :
       {Eigen::Vector3d(0.05, 0.01, 1.0), Eigen::Vector3d(-0.3, 0.1, 0.9),
        Eigen::Vector3d(0.1, 0.0, -1.0)}) {
    const Rigid3d world_from_cam = RandomPose(rng, 0.4, 5.0);
    const Eigen::Vector3d d_w = world_from_cam.rotation() * d_cam.normalized();
    const Eigen::Vector2d vp(650.0, 170.0);
    PoseBlock pose = ToPoseBlock(world_from_cam);
    std::array<double, 3> dir = {d_w.x(), d_w.y(), d_w.z()};
    DirectionProjectionFreeCost free(camera, vp, kSqrtInfo, 0.05);
    DirectionProjectionAnalyticCost fixed(camera, vp, d_w, kSqrtInfo, 0.05);
    double r_free[2], r_fixed[2], j_pose_free[14], j_dir[6], j_pose_fixed[14];
    double* jf[2] = {j_pose_free, j_dir};
    double* jx[1] = {j_pose_fixed};
    const double* pf[2] = {pose.data(), dir.data()};
    const double* px[1] = {pose.data()};
    ASSERT_TRUE(free.Evaluate(pf, r_free, jf));
    ASSERT_TRUE(fixed.Evaluate(px, r_fixed, jx));
    for (int i = 0; i < 2; ++i) EXPECT_DOUBLE_EQ(r_free[i], r_fixed[i]);
    for (int i = 0; i < 14; ++i) EXPECT_DOUBLE_EQ(j_pose_free[i], j_pose_fixed[i]);
    std::string log;
    EXPECT_LT(CheckGradient(free, {true, false}, {pose.data(), dir.data()}, &log), 1e-5) << log;
    // Translation columns are exactly zero: e_D constrains the rotation only.
    for (int row = 0; row < 2; ++row)
      for (int col = 4; col < 7; ++col) EXPECT_EQ(j_pose_free[row * 7 + col], 0.0);
  }
}

// The ray form of e_D: zero where the ray is R_wn^T d_w (either sign), |r| / s equals the angle
// for a small rotation away, and both Jacobians match numeric differences, also for a vertical
// ray (a VP at infinity in the image, where the pixel form cannot be used).
TEST(DirectionAngleFreeCost, ZeroOnTheRayAngleMagnitudeAndJacobians) {
  std::mt19937 rng(9);
  for (const Eigen::Vector3d& ray :
       {Eigen::Vector3d(0.0, -1.0, 0.0), Eigen::Vector3d(0.01, -1.0, 0.004),
        Eigen::Vector3d(0.1, 0.05, 1.0), Eigen::Vector3d(1.0, 0.0, 0.0)}) {
    const Rigid3d world_from_cam = RandomPose(rng, 0.4, 5.0);
    const Eigen::Vector3d d_w = world_from_cam.rotation() * ray.normalized();
    PoseBlock pose = ToPoseBlock(world_from_cam);
    const double s = 2.0;
    DirectionAngleFreeCost cost(ray, s);
    double r[2];
    for (const double sign : {1.0, -1.0}) {
      std::array<double, 3> dir = {sign * d_w.x(), sign * d_w.y(), sign * d_w.z()};
      const double* p[2] = {pose.data(), dir.data()};
      ASSERT_TRUE(cost.Evaluate(p, r, nullptr));
      EXPECT_NEAR(r[0], 0.0, 1e-12);
      EXPECT_NEAR(r[1], 0.0, 1e-12);
    }
    // d_w turned by 0.01 rad about an axis normal to it.
    const Eigen::Vector3d axis = d_w.unitOrthogonal();
    const Eigen::Vector3d turned = Eigen::AngleAxisd(0.01, axis) * d_w;
    std::array<double, 3> dir = {turned.x(), turned.y(), turned.z()};
    const double* p[2] = {pose.data(), dir.data()};
    ASSERT_TRUE(cost.Evaluate(p, r, nullptr));
    EXPECT_NEAR(std::hypot(r[0], r[1]) / s, 0.01, 1e-6);
    std::string log;
    EXPECT_LT(CheckGradient(cost, {true, false}, {pose.data(), dir.data()}, &log), 1e-5) << log;
    // Translation columns are exactly zero: the ray constrains the rotation only.
    double j_pose[14], j_dir[6];
    double* j[2] = {j_pose, j_dir};
    ASSERT_TRUE(cost.Evaluate(p, r, j));
    for (int row = 0; row < 2; ++row)
      for (int col = 4; col < 7; ++col) EXPECT_EQ(j_pose[row * 7 + col], 0.0);
  }
}

}  // namespace
}  // namespace jvl::optim
