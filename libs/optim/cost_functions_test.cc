#include "optim/cost_functions.h"

#include <gtest/gtest.h>

#include <memory>

#include "optim/test_util.h"

namespace jvl::optim {
namespace {

using testing::CheckGradient;
using testing::KittiLikeCamera;
using testing::RandomPose;

// Evaluates a cost function; optionally fills row-major Jacobians.
std::vector<double> Residuals(const ceres::CostFunction& cost, std::vector<double*> params,
                              std::vector<std::vector<double>>* jacobians = nullptr) {
  std::vector<double> r(cost.num_residuals());
  std::vector<double*> jac_ptrs;
  if (jacobians != nullptr) {
    jacobians->clear();
    for (int32_t size : cost.parameter_block_sizes()) {
      jacobians->emplace_back(static_cast<size_t>(size * cost.num_residuals()));
    }
    for (auto& j : *jacobians) jac_ptrs.push_back(j.data());
  }
  EXPECT_TRUE(cost.Evaluate(params.data(), r.data(), jacobians ? jac_ptrs.data() : nullptr));
  return r;
}

TEST(VisualReprojectionCost, ZeroAtTruthSignedWhenPerturbedAndJacobianMatches) {
  std::mt19937 rng(1);
  const PinholeCamera camera = KittiLikeCamera();
  const Rigid3d world_from_cam = RandomPose(rng, 0.3, 5.0);
  const Eigen::Vector3d x_c(1.5, -0.7, 12.0);
  const Eigen::Vector3d x_w = world_from_cam * x_c;
  const Eigen::Vector2d uv = camera.Project(x_c);
  std::unique_ptr<ceres::CostFunction> cost(VisualReprojectionCost::Create(camera, uv, 1.0 / 1.44));
  PoseBlock pose = ToPoseBlock(world_from_cam);
  std::array<double, 3> point = {x_w.x(), x_w.y(), x_w.z()};
  std::vector<double> r = Residuals(*cost, {pose.data(), point.data()});
  EXPECT_NEAR(r[0], 0.0, 1e-9);
  EXPECT_NEAR(r[1], 0.0, 1e-9);

  // Moving the point 0.1 m along the camera's +x raises the predicted u: r_u = u_obs - u < 0,
  // by fx * 0.1 / 12 px scaled by the square-root information.
  const Eigen::Vector3d moved = world_from_cam * (x_c + Eigen::Vector3d(0.1, 0, 0));
  point = {moved.x(), moved.y(), moved.z()};
  r = Residuals(*cost, {pose.data(), point.data()});
  EXPECT_NEAR(r[0], -camera.fx * 0.1 / 12.0 / 1.44, 1e-9);
  EXPECT_NEAR(r[1], 0.0, 1e-9);

  std::string log;
  EXPECT_LT(CheckGradient(*cost, {true, false}, {pose.data(), point.data()}, &log), 1e-6) << log;
}

TEST(VisualReprojectionCost, PointBehindCameraFailsEvaluation) {
  const PinholeCamera camera = KittiLikeCamera();
  std::unique_ptr<ceres::CostFunction> cost(
      VisualReprojectionCost::Create(camera, {600, 180}, 1.0));
  PoseBlock pose = ToPoseBlock(Rigid3d());
  std::array<double, 3> point = {0, 0, -5};
  double r[2];
  std::vector<double*> params = {pose.data(), point.data()};
  EXPECT_FALSE(cost->Evaluate(params.data(), r, nullptr));
}

struct ImlsSetup {
  Rigid3d world_from_n, world_from_c;
  Eigen::Vector3d p_x, c_p_y, c_normal;
};

ImlsSetup MakeImls(std::mt19937& rng) {
  ImlsSetup s;
  s.world_from_n = RandomPose(rng, 0.2, 3.0);
  s.world_from_c = RandomPose(rng, 0.2, 3.0);
  s.c_normal = Eigen::Vector3d(0.2, -0.9, 0.3).normalized();
  s.c_p_y = Eigen::Vector3d(4.0, 1.5, 10.0);
  // p_x: a point on the tangent plane at c_p_y, seen from n.
  const Eigen::Vector3d tangent = s.c_normal.cross(Eigen::Vector3d::UnitZ()).normalized();
  s.p_x = s.world_from_n.Inverse() * (s.world_from_c * (s.c_p_y + 0.3 * tangent));
  return s;
}

TEST(PointToImlsCost, ZeroOnSurfaceSignedAlongNormalAndJacobianMatches) {
  std::mt19937 rng(2);
  const ImlsSetup s = MakeImls(rng);
  std::unique_ptr<ceres::CostFunction> cost(
      PointToImlsCost::Create(s.p_x, s.c_p_y, s.c_normal, 20.0));
  PoseBlock pose_n = ToPoseBlock(s.world_from_n);
  PoseBlock pose_c = ToPoseBlock(s.world_from_c);
  EXPECT_NEAR(Residuals(*cost, {pose_n.data(), pose_c.data()})[0], 0.0, 1e-9);

  // Shift keyframe n by 0.05 m along the world normal: the point moves 0.05 m off the surface
  // on the normal's side, r = +20 * 0.05.
  const Eigen::Vector3d world_normal = s.world_from_c.rotation() * s.c_normal;
  const Rigid3d shifted(s.world_from_n.rotation(),
                        s.world_from_n.translation() + 0.05 * world_normal);
  PoseBlock pose_n_shifted = ToPoseBlock(shifted);
  EXPECT_NEAR(Residuals(*cost, {pose_n_shifted.data(), pose_c.data()})[0], 1.0, 1e-9);

  std::string log;
  EXPECT_LT(CheckGradient(*cost, {true, true}, {pose_n_shifted.data(), pose_c.data()}, &log), 1e-6)
      << log;
}

TEST(PointToImlsCost, InvariantToACommonRigidMotionOfBothPoses) {
  std::mt19937 rng(3);
  const ImlsSetup s = MakeImls(rng);
  std::unique_ptr<ceres::CostFunction> cost(
      PointToImlsCost::Create(s.p_x + Eigen::Vector3d(0.1, 0.2, -0.1), s.c_p_y, s.c_normal, 1.0));
  PoseBlock pose_n = ToPoseBlock(s.world_from_n);
  PoseBlock pose_c = ToPoseBlock(s.world_from_c);
  const double r0 = Residuals(*cost, {pose_n.data(), pose_c.data()})[0];
  EXPECT_GT(std::abs(r0), 1e-3);
  for (int trial = 0; trial < 5; ++trial) {
    const Rigid3d g = RandomPose(rng, 1.0, 50.0);
    PoseBlock moved_n = ToPoseBlock(g * s.world_from_n);
    PoseBlock moved_c = ToPoseBlock(g * s.world_from_c);
    EXPECT_NEAR(Residuals(*cost, {moved_n.data(), moved_c.data()})[0], r0, 1e-9);
  }
}

TEST(PointToSurfaceCost, ZeroOnSurfaceSignedAlongNormalBlindAlongItAndJacobianMatches) {
  std::mt19937 rng(5);
  const Rigid3d world_from_k = RandomPose(rng, 0.3, 5.0);
  const Eigen::Vector3d k_p_y(2.0, -1.0, 10.0);
  const Eigen::Vector3d k_normal = Eigen::Vector3d(0.3, 0.1, -1.0).normalized();
  std::unique_ptr<ceres::CostFunction> cost(PointToSurfaceCost::Create(k_p_y, k_normal, 20.0));
  PoseBlock pose = ToPoseBlock(world_from_k);
  const auto at = [&](const Eigen::Vector3d& k_x) {
    const Eigen::Vector3d w = world_from_k * k_x;
    std::array<double, 3> point = {w.x(), w.y(), w.z()};
    const std::vector<double> r = Residuals(*cost, {pose.data(), point.data()});
    EXPECT_EQ(r.size(), 2u);
    EXPECT_EQ(r[1], 0.0);  // the padding row (reprojection-sized blocks on map points)
    return r[0];
  };
  EXPECT_NEAR(at(k_p_y), 0.0, 1e-9);
  // 0.05 m off the surface on the normal's side: r = +20 * 0.05; along the surface: 0.
  EXPECT_NEAR(at(k_p_y + 0.05 * k_normal), 1.0, 1e-9);
  EXPECT_NEAR(at(k_p_y - 0.05 * k_normal), -1.0, 1e-9);
  const Eigen::Vector3d along = k_normal.cross(Eigen::Vector3d::UnitY()).normalized();
  EXPECT_NEAR(at(k_p_y + 0.7 * along), 0.0, 1e-9);

  const Eigen::Vector3d w = world_from_k * (k_p_y + 0.05 * k_normal + 0.3 * along);
  std::array<double, 3> point = {w.x(), w.y(), w.z()};
  std::string log;
  EXPECT_LT(CheckGradient(*cost, {true, false}, {pose.data(), point.data()}, &log), 1e-6) << log;
}

TEST(DirectionProjectionCost, ZeroWhenDirectionProjectsOntoVp) {
  std::mt19937 rng(4);
  const PinholeCamera camera = KittiLikeCamera();
  const Rigid3d world_from_cam = RandomPose(rng, 0.3, 10.0);
  const Eigen::Vector3d d_cam = Eigen::Vector3d(0.1, 0.02, 1.0).normalized();
  const Eigen::Vector3d d_w = world_from_cam.rotation() * d_cam;
  const Eigen::Vector2d vp = camera.Project(d_cam);
  std::unique_ptr<ceres::CostFunction> cost(
      DirectionProjectionCost::Create(camera, vp, d_w, Eigen::Vector2d(0.5, 0.5), 0.05));
  PoseBlock pose = ToPoseBlock(world_from_cam);
  std::vector<double> r = Residuals(*cost, {pose.data()});
  EXPECT_NEAR(r[0], 0.0, 1e-9);
  EXPECT_NEAR(r[1], 0.0, 1e-9);
  // The opposite (unoriented) direction has the same vanishing point.
  std::unique_ptr<ceres::CostFunction> flipped(
      DirectionProjectionCost::Create(camera, vp, -d_w, Eigen::Vector2d(0.5, 0.5), 0.05));
  r = Residuals(*flipped, {pose.data()});
  EXPECT_NEAR(r[0], 0.0, 1e-9);
  // Translation does not matter at all.
  PoseBlock moved = pose;
  moved[4] += 100.0;
  moved[6] -= 30.0;
  r = Residuals(*cost, {moved.data()});
  EXPECT_NEAR(r[0], 0.0, 1e-9);
}

TEST(DirectionProjectionCost, YawSignTranslationDerivativeZeroAndJacobianMatches) {
  const PinholeCamera camera = KittiLikeCamera();
  const Eigen::Vector3d d_w = Eigen::Vector3d::UnitZ();  // straight ahead
  std::unique_ptr<ceres::CostFunction> cost(DirectionProjectionCost::Create(
      camera, {camera.cx, camera.cy}, d_w, Eigen::Vector2d(1.0, 1.0), 0.05));
  // Camera turned right (rotation by +yaw about its y axis, optical axis towards +x): the road
  // direction appears left of the principal point, predicted u < cx, so r_u = cx - u > 0.
  const double yaw = 0.01;
  const Rigid3d turned(ExpSO3(Eigen::Vector3d(0, yaw, 0)), Eigen::Vector3d(1, 2, 3));
  PoseBlock pose = ToPoseBlock(turned);
  std::vector<std::vector<double>> jac;
  const std::vector<double> r = Residuals(*cost, {pose.data()}, &jac);
  EXPECT_NEAR(r[0], camera.fx * std::tan(yaw), 1e-6);
  EXPECT_NEAR(r[1], 0.0, 1e-9);
  for (int row = 0; row < 2; ++row) {
    for (int col = 4; col < 7; ++col) EXPECT_EQ(jac[0][row * 7 + col], 0.0);
  }
  std::string log;
  EXPECT_LT(CheckGradient(*cost, {true}, {pose.data()}, &log), 1e-6) << log;
}

TEST(DirectionProjectionCost, FiniteWhenDirectionIsParallelToTheImagePlane) {
  const PinholeCamera camera = KittiLikeCamera();
  std::unique_ptr<ceres::CostFunction> cost(DirectionProjectionCost::Create(
      camera, {camera.cx, camera.cy}, Eigen::Vector3d::UnitX(), Eigen::Vector2d(1.0, 1.0), 0.05));
  PoseBlock pose = ToPoseBlock(Rigid3d());
  std::vector<std::vector<double>> jac;
  const std::vector<double> r = Residuals(*cost, {pose.data()}, &jac);
  EXPECT_TRUE(std::isfinite(r[0]) && std::isfinite(r[1]));
  EXPECT_NEAR(r[0], -camera.fx / 0.05, 1e-6);  // clamped z = min_z: large, finite
  for (double j : jac[0]) EXPECT_TRUE(std::isfinite(j));
}

TEST(RelativePoseCost, ZeroAtTheMeasuredMotionKnownValuesAndJacobianMatches) {
  std::mt19937 rng(5);
  const Rigid3d world_from_i = RandomPose(rng, 0.5, 20.0);
  const Rigid3d i_from_j = RandomPose(rng, 0.05, 2.0);
  const Rigid3d world_from_j = world_from_i * i_from_j;
  std::unique_ptr<ceres::CostFunction> cost(
      RelativePoseCost::Create(i_from_j.rotation(), i_from_j.translation(),
                               Eigen::Vector3d::Constant(1.0 / 0.01), Eigen::Vector3d(10, 20, 5)));
  PoseBlock pose_i = ToPoseBlock(world_from_i);
  PoseBlock pose_j = ToPoseBlock(world_from_j);
  for (const double r : Residuals(*cost, {pose_i.data(), pose_j.data()})) EXPECT_NEAR(r, 0.0, 1e-9);

  // j moved 0.05 m along the axis x of the measured j frame: r_t = (0.05 x 10, 0, 0).
  const Rigid3d moved_j =
      world_from_j * Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.05, 0, 0));
  PoseBlock pose_moved = ToPoseBlock(moved_j);
  std::vector<double> r = Residuals(*cost, {pose_i.data(), pose_moved.data()});
  EXPECT_NEAR(r[3], 0.5, 1e-9);
  EXPECT_NEAR(r[4], 0.0, 1e-9);
  EXPECT_NEAR(r[0], 0.0, 1e-9);
  // j turned 0.002 rad about its own z: the rotation part is (0, 0, 0.002) / 0.01 to 2nd order.
  const Rigid3d turned_j =
      world_from_j * Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.002, Eigen::Vector3d::UnitZ())),
                             Eigen::Vector3d::Zero());
  PoseBlock pose_turned = ToPoseBlock(turned_j);
  r = Residuals(*cost, {pose_i.data(), pose_turned.data()});
  EXPECT_NEAR(r[2], 0.2, 1e-6);
  EXPECT_NEAR(r[3], 0.0, 1e-9);

  std::string log;
  EXPECT_LT(CheckGradient(*cost, {true, true}, {pose_i.data(), pose_moved.data()}, &log), 1e-6)
      << log;
}

TEST(RelativePoseCost, InvariantToACommonRigidMotionOfBothPoses) {
  std::mt19937 rng(6);
  const Rigid3d world_from_i = RandomPose(rng, 0.5, 20.0);
  const Rigid3d world_from_j = world_from_i * RandomPose(rng, 0.05, 2.0);
  const Rigid3d measured = RandomPose(rng, 0.05, 2.0);
  std::unique_ptr<ceres::CostFunction> cost(
      RelativePoseCost::Create(measured.rotation(), measured.translation(),
                               Eigen::Vector3d(100, 50, 200), Eigen::Vector3d(10, 20, 5)));
  PoseBlock pose_i = ToPoseBlock(world_from_i);
  PoseBlock pose_j = ToPoseBlock(world_from_j);
  const std::vector<double> r0 = Residuals(*cost, {pose_i.data(), pose_j.data()});
  for (int trial = 0; trial < 5; ++trial) {
    const Rigid3d g = RandomPose(rng, 1.0, 50.0);
    PoseBlock moved_i = ToPoseBlock(g * world_from_i);
    PoseBlock moved_j = ToPoseBlock(g * world_from_j);
    const std::vector<double> r = Residuals(*cost, {moved_i.data(), moved_j.data()});
    for (size_t k = 0; k < r.size(); ++k) EXPECT_NEAR(r[k], r0[k], 1e-8);
  }
}

TEST(MotionSmoothnessCost, ZeroOnAConstantTurnKnownValueAndJacobianMatches) {
  // A car on a circle at constant speed and turn rate: 1.2 m and 0.02 rad per frame (about the
  // camera's y axis, down), keyframes 2 and 3 frames apart.
  std::mt19937 rng(7);
  const Rigid3d start = RandomPose(rng, 0.5, 20.0);
  const double radius = 1.2 / 0.02;
  auto on_circle = [&](double frames) {
    const double phi = 0.02 * frames;
    return start * Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitY())),
                           radius * Eigen::Vector3d(1.0 - std::cos(phi), 0.0, std::sin(phi)));
  };
  const Eigen::Vector3d sigma(0.004, 0.003, 0.009);
  std::unique_ptr<ceres::CostFunction> cost(
      MotionSmoothnessCost::Create(2.0, 3.0, sigma.cwiseInverse()));
  PoseBlock a = ToPoseBlock(on_circle(0)), b = ToPoseBlock(on_circle(2)),
            c = ToPoseBlock(on_circle(5));
  // The chords shrink by (n phi)^2 / 24 of the speed: 0.1 mm per frame between the two spacings.
  std::vector<double> r = Residuals(*cost, {a.data(), b.data(), c.data()});
  for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(r[k]) * sigma(k), 1.5e-4) << k;
  // Expressed in a's frame instead of the midway one, the lateral part would be 12 mm per frame.

  // c moved 0.03 m forward along the chord b -> c: v_bc grows by 0.01 m per frame along z.
  const Rigid3d b_pose = on_circle(2), c_pose = on_circle(5);
  const Eigen::Vector3d chord = (c_pose.translation() - b_pose.translation()).normalized();
  const Rigid3d moved_c(c_pose.rotation(), c_pose.translation() + 0.03 * chord);
  PoseBlock c_moved = ToPoseBlock(moved_c);
  const std::vector<double> r0 = r;
  r = Residuals(*cost, {a.data(), b.data(), c_moved.data()});
  EXPECT_NEAR(r[0] - r0[0], 0.0, 1e-6);
  EXPECT_NEAR(r[1] - r0[1], 0.0, 1e-6);
  EXPECT_NEAR(r[2] - r0[2], 0.01 / 0.009, 1e-6);

  std::string log;
  EXPECT_LT(CheckGradient(*cost, {true, true, true}, {a.data(), b.data(), c_moved.data()}, &log),
            1e-6)
      << log;
}

TEST(MotionSmoothnessCost, InvariantToACommonRigidMotionAndBlindToAConstantVelocity) {
  std::mt19937 rng(8);
  const Rigid3d a_pose = RandomPose(rng, 0.5, 20.0);
  const Rigid3d b_pose = a_pose * RandomPose(rng, 0.05, 2.0);
  const Rigid3d c_pose = b_pose * RandomPose(rng, 0.05, 2.0);
  std::unique_ptr<ceres::CostFunction> cost(
      MotionSmoothnessCost::Create(1.0, 1.0, Eigen::Vector3d(200, 300, 100)));
  PoseBlock a = ToPoseBlock(a_pose), b = ToPoseBlock(b_pose), c = ToPoseBlock(c_pose);
  const std::vector<double> r0 = Residuals(*cost, {a.data(), b.data(), c.data()});
  EXPECT_GT(std::abs(r0[0]) + std::abs(r0[1]) + std::abs(r0[2]), 1.0);  // not a constant motion
  for (int trial = 0; trial < 5; ++trial) {
    const Rigid3d g = RandomPose(rng, 1.0, 50.0);
    PoseBlock ga = ToPoseBlock(g * a_pose), gb = ToPoseBlock(g * b_pose),
              gc = ToPoseBlock(g * c_pose);
    const std::vector<double> r = Residuals(*cost, {ga.data(), gb.data(), gc.data()});
    for (size_t k = 0; k < r.size(); ++k) EXPECT_NEAR(r[k], r0[k], 1e-8);
  }
  // The same motion repeated (b = a * M, c = b * M) is a constant body-frame velocity: zero.
  const Rigid3d step = RandomPose(rng, 0.05, 2.0);
  PoseBlock b2 = ToPoseBlock(a_pose * step), c2 = ToPoseBlock(a_pose * step * step);
  for (const double r : Residuals(*cost, {a.data(), b2.data(), c2.data()}))
    EXPECT_NEAR(r, 0.0, 1e-9);
}

}  // namespace
}  // namespace jvl::optim
