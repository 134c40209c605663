#include "optim/schur_lm.h"

#include <ceres/sized_cost_function.h>
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <random>

#include "optim/joint_problem.h"
#include "optim/test_util.h"
#include "optim/toy_road.h"

namespace jvl::optim {
namespace {

using testing::MakeToyRoad;
using testing::MaxPoseDifference;
using testing::ToyRoad;

double MaxPointDifference(const std::vector<Eigen::Vector3d>& a,
                          const std::vector<Eigen::Vector3d>& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, (a[i] - b[i]).norm());
  return worst;
}

// The same problem through Ceres' DENSE_SCHUR and through SolveSchurLm: same Levenberg-Marquardt,
// so the same iterations and the same solution up to rounding.
void ExpectSameAsCeres(const JointProblemInput& input, const JointProblemOptions& options) {
  SolveOptions ceres_dense, native;
  ceres_dense.schur_lm = false;
  const JointSolveResult a = OptimizeJoint(input, options, ceres_dense);
  const JointSolveResult b = OptimizeJoint(input, options, native);
  EXPECT_EQ(a.linear_solver, "DENSE_SCHUR");
  EXPECT_EQ(b.linear_solver, "SCHUR_LM");
  ASSERT_TRUE(a.usable && b.usable) << a.termination << "\n" << b.termination;
  EXPECT_EQ(a.iterations, b.iterations) << a.termination << "\n" << b.termination;
  EXPECT_NEAR(a.before.total, b.before.total, 1e-12 * a.before.total);
  EXPECT_NEAR(a.after.total, b.after.total, 1e-9 * a.after.total);
  EXPECT_LT(a.after.total, 0.5 * a.before.total);
  EXPECT_LT(MaxPoseDifference(a.poses, b.poses), 1e-7);
  EXPECT_LT(MaxPointDifference(a.map_points, b.map_points), 1e-6);
}

TEST(SchurLm, TakesCeresStepsOnTheToyRoad) {
  // Visual (Huber) + IMLS pairs, one fixed keyframe.
  ExpectSameAsCeres(MakeToyRoad(false).input, {});
}

TEST(SchurLm, TakesCeresStepsWithDirectionsAndSeveralFixedKeyframes) {
  ToyRoad toy = MakeToyRoad(true);
  toy.input.fixed = {0, 1, 2};
  JointProblemOptions options;
  options.visual_huber = 1.0;  // more observations in the kernel's linear part
  ExpectSameAsCeres(toy.input, options);
}

TEST(SchurLm, TakesCeresStepsAfterRejectedSteps) {
  // Poses far from the solution: the first, nearly Gauss-Newton steps overshoot and are
  // rejected, and the damped steps after them are built from the same Jacobian and residuals.
  ToyRoad toy = MakeToyRoad(false);
  std::mt19937 rng(7);
  for (auto& [id, pose] : toy.input.poses) {
    if (id != 0) pose = pose * testing::RandomPose(rng, 0.25, 2.0);
  }
  JointProblemOptions options;
  JointProblem jp = BuildJointProblem(toy.input, options);
  std::vector<double*> points;
  for (auto& p : jp.map_points) points.push_back(p.data());
  const SchurLmSummary s = SolveSchurLm(*jp.problem, points, {});
  ASSERT_TRUE(s.usable) << s.report;
  EXPECT_LT(s.successful_steps, s.iterations) << s.report;
  ExpectSameAsCeres(toy.input, options);
}

TEST(SchurLm, SameBytesOnEveryRun) {
  const ToyRoad toy = MakeToyRoad(false);
  SolveOptions solve;
  solve.threads = 2;
  const JointSolveResult a = OptimizeJoint(toy.input, {}, solve);
  const JointSolveResult b = OptimizeJoint(toy.input, {}, solve);
  EXPECT_EQ(MaxPoseDifference(a.poses, b.poses), 0.0);
  EXPECT_EQ(MaxPointDifference(a.map_points, b.map_points), 0.0);
  EXPECT_EQ(a.after.total, b.after.total);
}

TEST(SchurLm, IterationLimitStopsUsably) {
  const ToyRoad toy = MakeToyRoad(true);
  SolveOptions solve;
  solve.max_iterations = 1;
  const JointSolveResult r = OptimizeJoint(toy.input, {}, solve);
  EXPECT_TRUE(r.usable);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_NE(r.termination.find("NO_CONVERGENCE"), std::string::npos) << r.termination;
  EXPECT_LT(r.after.total, r.before.total);
}

// r = x - target for a 3-vector point block; fails (returns false) when `fail` is set.
class PointCost : public ceres::SizedCostFunction<3, 3> {
 public:
  PointCost(const Eigen::Vector3d& target, const bool* fail) : target_(target), fail_(fail) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (*fail_) return false;
    for (int i = 0; i < 3; ++i) residuals[i] = parameters[0][i] - target_[i];
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(jacobians[0]).setIdentity();
    }
    return true;
  }

 private:
  Eigen::Vector3d target_;
  const bool* fail_;
};

// r = point - offset (a 3-vector "camera" block without manifold): couples points and a camera.
class OffsetCost : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  explicit OffsetCost(const Eigen::Vector3d& measured) : measured_(measured) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (int i = 0; i < 3; ++i) residuals[i] = parameters[1][i] - parameters[0][i] - measured_[i];
    if (jacobians != nullptr) {
      using Jacobian = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>;
      if (jacobians[0] != nullptr) {
        Jacobian j(jacobians[0]);
        j = -Eigen::Matrix3d::Identity();
      }
      if (jacobians[1] != nullptr) {
        Jacobian j(jacobians[1]);
        j.setIdentity();
      }
    }
    return true;
  }

 private:
  Eigen::Vector3d measured_;
};

TEST(SchurLm, SolvesALinearProblemExactlyAndLeavesValuesOnFailure) {
  // A camera (offset) and points; the points' priors and the offsets determine everything.
  std::array<double, 3> camera = {0.5, -0.2, 0.1};
  std::vector<std::array<double, 3>> points(4, {0.0, 0.0, 0.0});
  bool fail = false;
  ceres::Problem problem;
  const Eigen::Vector3d offset(1.0, 2.0, 3.0);
  std::vector<double*> eliminate;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p(static_cast<double>(i), 1.0, -1.0);
    problem.AddResidualBlock(new PointCost(p + offset, &fail), nullptr, points[i].data());
    problem.AddResidualBlock(new OffsetCost(p), nullptr, camera.data(), points[i].data());
    eliminate.push_back(points[i].data());
  }
  ASSERT_TRUE(SchurLmApplies(problem, eliminate, 6));
  const SchurLmSummary s = SolveSchurLm(problem, eliminate, {});
  ASSERT_TRUE(s.usable && s.converged) << s.report;
  EXPECT_LT(s.final_cost, 1e-20);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(camera[k], offset[k], 1e-9);
  for (size_t i = 0; i < points.size(); ++i)
    EXPECT_NEAR(points[i][0], static_cast<double>(i) + offset[0], 1e-9);

  // A failing cost function: not usable, values untouched.
  const double point0 = points[0][0];
  camera = {7.0, 8.0, 9.0};
  fail = true;
  const SchurLmSummary f = SolveSchurLm(problem, eliminate, {});
  EXPECT_FALSE(f.usable);
  EXPECT_EQ(camera[0], 7.0);
  EXPECT_EQ(points[0][0], point0);
}

TEST(SchurLmApplies, RefusesTwoEliminatedBlocksInOneResidualAndLargeReducedSystems) {
  std::array<double, 3> a = {0, 0, 0}, b = {1, 1, 1};
  ceres::Problem problem;
  problem.AddResidualBlock(new OffsetCost(Eigen::Vector3d::Ones()), nullptr, a.data(), b.data());
  EXPECT_FALSE(SchurLmApplies(problem, {a.data(), b.data()}, 64));
  EXPECT_TRUE(SchurLmApplies(problem, {b.data()}, 3));
  EXPECT_FALSE(SchurLmApplies(problem, {b.data()}, 2));  // camera a: 3 > 2
}

}  // namespace
}  // namespace jvl::optim
