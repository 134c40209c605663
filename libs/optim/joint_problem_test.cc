#include "optim/joint_problem.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/check.h"
#include "optim/test_util.h"
#include "optim/toy_road.h"

namespace jvl::optim {
namespace {

using testing::MakeToyRoad;
using testing::MaxPoseDifference;
using testing::ToyRoad;
constexpr int kKeyframes = testing::kToyKeyframes;

struct Errors {
  double max_yaw_deg = 0.0;
  double ape_m = 0.0;  // RMSE of positions; keyframe 0 is fixed at the truth (no alignment)
};

Errors ComputeErrors(const std::map<int64_t, Rigid3d>& truth,
                     const std::map<int64_t, Rigid3d>& estimate) {
  Errors e;
  double sum = 0.0;
  for (const auto& [id, pose] : truth) {
    const Rigid3d& est = estimate.at(id);
    e.max_yaw_deg = std::max(
        e.max_yaw_deg, RotationAngle(pose.rotation().conjugate() * est.rotation()) * 180.0 / M_PI);
    sum += (est.translation() - pose.translation()).squaredNorm();
  }
  e.ape_m = std::sqrt(sum / static_cast<double>(truth.size()));
  return e;
}

std::string Str(const Eigen::Vector3d& v) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "%.2f %.2f %.2f", v.x(), v.y(), v.z());
  return buf;
}

TEST(JointProblem, DirectionPriorsRemoveAYawDriftTheLocalTermsCannotSee) {
  const ToyRoad local_only = MakeToyRoad(false);
  const ToyRoad with_dirs = MakeToyRoad(true);
  const Errors prior = ComputeErrors(local_only.truth, local_only.input.poses);
  const JointProblemOptions options;
  SolveOptions solve;
  solve.max_iterations = 100;
  const JointSolveResult a = OptimizeJoint(local_only.input, options, solve);
  const JointSolveResult b = OptimizeJoint(with_dirs.input, options, solve);
  ASSERT_TRUE(a.usable && b.usable) << a.termination << "\n" << b.termination;
  const Errors ea = ComputeErrors(local_only.truth, a.poses);
  const Errors eb = ComputeErrors(with_dirs.truth, b.poses);
  std::printf("prior: max yaw %.3f deg, APE %.3f m\n", prior.max_yaw_deg, prior.ape_m);
  std::printf("local terms only: max yaw %.3f deg, APE %.3f m (%d it, %.3f s)\n", ea.max_yaw_deg,
              ea.ape_m, a.iterations, a.time_s);
  std::printf("with directions: max yaw %.3f deg, APE %.3f m (%d it, %.3f s, gamma %.1f)\n",
              eb.max_yaw_deg, eb.ape_m, b.iterations, b.time_s, b.weights.gamma);
  for (int64_t k : {5, 15, 29}) {
    std::printf("kf %ld truth %s | a %s | b %s\n", static_cast<long>(k),
                Str(with_dirs.truth.at(k).translation()).c_str(),
                Str(a.poses.at(k).translation()).c_str(), Str(b.poses.at(k).translation()).c_str());
  }
  // The local terms keep the drift (they were generated from the drifted prior).
  EXPECT_GT(ea.max_yaw_deg, 0.8 * prior.max_yaw_deg);
  EXPECT_GT(ea.ape_m, 0.8 * prior.ape_m);
  // Direction priors remove most of it.
  EXPECT_LT(eb.max_yaw_deg, 0.2 * prior.max_yaw_deg);
  // The position error halves: what remains is the lateral offset the biased local terms still
  // push for (they encode the drifted relative rotations; see docs/optimization.md).
  EXPECT_LT(eb.ape_m, 0.6 * ea.ape_m);
  EXPECT_LT(eb.ape_m, 0.6 * prior.ape_m);
  EXPECT_LT(b.after.direction.rms, 0.1 * b.before.direction.rms);
  EXPECT_EQ(b.before.direction.count, kKeyframes - 1);
  EXPECT_GT(b.before.visual.count, 2000);
  EXPECT_EQ(b.before.imls.count, 30 * (kKeyframes - 1));
  // Gauge: keyframe 0 is fixed.
  EXPECT_EQ(b.poses.at(0).ToArray(), with_dirs.input.poses.at(0).ToArray());
}

TEST(JointProblem, ThreadCountDoesNotChangeTheResult) {
  const ToyRoad toy = MakeToyRoad(true);
  SolveOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const JointSolveResult a = OptimizeJoint(toy.input, {}, one);
  const JointSolveResult b = OptimizeJoint(toy.input, {}, two);
  const JointSolveResult c = OptimizeJoint(toy.input, {}, two);
  // Ceres runs on one thread whatever `threads` says (joint_stats.cc): the results are the same
  // to the last bit.
  EXPECT_EQ(MaxPoseDifference(a.poses, b.poses), 0.0);
  EXPECT_EQ(MaxPoseDifference(b.poses, c.poses), 0.0);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.after.total, b.after.total);
  EXPECT_EQ(a.before.total, c.before.total);
}

TEST(JointProblem, AnalyticAndAutodiffJacobiansReachTheSameSolution) {
  const ToyRoad toy = MakeToyRoad(true);
  JointProblemOptions analytic, autodiff;
  autodiff.analytic_jacobians = false;
  const JointSolveResult a = OptimizeJoint(toy.input, analytic, {});
  const JointSolveResult b = OptimizeJoint(toy.input, autodiff, {});
  EXPECT_LT(MaxPoseDifference(a.poses, b.poses), 1e-7);
  EXPECT_NEAR(a.before.total, b.before.total, 1e-9 * a.before.total);
}

TEST(JointProblem, WeightsFollowTheResidualCounts) {
  JointProblemOptions options;
  options.gamma_scale = 2.0;
  JointWeights w = ResolveWeights(options, 1000, 4000, 50);
  EXPECT_DOUBLE_EQ(w.alpha, 1.0);
  EXPECT_DOUBLE_EQ(w.beta, 0.25);
  EXPECT_DOUBLE_EQ(w.gamma, 40.0);
  w = ResolveWeights(options, 0, 4000, 50);  // no visual residuals: reference is max(N_L, N_D)
  EXPECT_DOUBLE_EQ(w.beta, 1.0);
  EXPECT_DOUBLE_EQ(w.gamma, 160.0);
  options.beta = 3.0;
  options.gamma = 0.5;
  w = ResolveWeights(options, 1000, 4000, 50);
  EXPECT_DOUBLE_EQ(w.beta, 3.0);
  EXPECT_DOUBLE_EQ(w.gamma, 0.5);
}

TEST(JointProblem, RejectsInconsistentInput) {
  ToyRoad toy = MakeToyRoad(true);
  JointProblemInput bad = toy.input;
  bad.imls[0].c = bad.imls[0].n;
  EXPECT_THROW(BuildJointProblem(bad, {}), Error);
  bad = toy.input;
  bad.directions[0].keyframe = 999;
  EXPECT_THROW(BuildJointProblem(bad, {}), Error);
  bad = toy.input;
  bad.directions[0].vp.x() = std::nan("");
  EXPECT_THROW(BuildJointProblem(bad, {}), Error);
  bad = toy.input;
  bad.observations[0].map_point = -1;
  EXPECT_THROW(BuildJointProblem(bad, {}), Error);
  bad = toy.input;
  bad.fixed = {12345};
  EXPECT_THROW(BuildJointProblem(bad, {}), Error);
  bad = toy.input;
  bad.point_surfaces.push_back({0, 0, Eigen::Vector3d(1, 0, 5), Eigen::Vector3d(2, 0, 0)});
  EXPECT_THROW(BuildJointProblem(bad, {}), Error);  // not a unit normal
  bad = toy.input;
  bad.point_surfaces.push_back({0, -1, Eigen::Vector3d(1, 0, 5), Eigen::Vector3d(1, 0, 0)});
  EXPECT_THROW(BuildJointProblem(bad, {}), Error);
  JointProblemOptions options;
  options.alpha = 0;
  EXPECT_THROW(BuildJointProblem(toy.input, options), Error);
  options = {};
  options.surface_sigma_m = 0;
  EXPECT_THROW(BuildJointProblem(toy.input, options), Error);
}

TEST(JointProblem, DropsObservationsBehindTheCameraAndFixesTheFirstPoseByDefault) {
  ToyRoad toy = MakeToyRoad(false);
  toy.input.fixed.clear();
  toy.input.map_points.push_back(Eigen::Vector3d(0, 0, -10));  // behind keyframe 0
  toy.input.observations.push_back(
      {0, static_cast<int32_t>(toy.input.map_points.size() - 1), Eigen::Vector2d(600, 180), 0});
  JointProblem jp = BuildJointProblem(toy.input, {});
  EXPECT_EQ(jp.dropped_observations, 1);
  EXPECT_EQ(jp.fixed, std::set<int64_t>{0});
  EXPECT_TRUE(jp.problem->IsParameterBlockConstant(jp.poses.at(0).data()));
  EXPECT_FALSE(jp.problem->IsParameterBlockConstant(jp.poses.at(1).data()));
  const JointSolveResult result = SolveJointProblem(jp, {});
  EXPECT_EQ(result.linear_solver, "SCHUR_LM");  // a handful of poses: the dense native solver
  EXPECT_TRUE(result.usable);
}

TEST(JointProblem, DenseAndSparseSchurComplementsGiveTheSameSolution) {
  ToyRoad toy = MakeToyRoad(false);
  SolveOptions dense, sparse;
  dense.schur_lm = false;  // Ceres' dense Schur complement (schur_lm_test.cc: the native one)
  sparse.dense_schur_max_blocks = 0;
  const JointSolveResult a = OptimizeJoint(toy.input, {}, dense);
  const JointSolveResult b = OptimizeJoint(toy.input, {}, sparse);
  EXPECT_EQ(a.linear_solver, "DENSE_SCHUR");
  EXPECT_EQ(b.linear_solver, "SPARSE_SCHUR");
  ASSERT_TRUE(a.usable && b.usable);
  EXPECT_NEAR(a.after.total, b.after.total, 1e-9 * (1 + b.after.total));
  for (const auto& [id, pose] : b.poses) {
    EXPECT_LT((a.poses.at(id).translation() - pose.translation()).norm(), 1e-7) << id;
  }
  sparse.dense_schur_max_blocks = -1;
  EXPECT_THROW(OptimizeJoint(toy.input, {}, sparse), Error);
}

TEST(JointProblem, VisualGateLeavesOutOutliersAndPointsWithoutDepth) {
  ToyRoad toy = MakeToyRoad(false);
  // Two points seen by keyframes 3 and 4; one observation of each is 40 px off.
  JointProblemInput& in = toy.input;
  const int64_t before = static_cast<int64_t>(in.observations.size());
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector3d p_w = in.poses[3] * Eigen::Vector3d(-4.0 + 8.0 * i, -1.0, 15.0);
    const int32_t id = static_cast<int32_t>(in.map_points.size());
    in.map_points.push_back(p_w);
    for (int64_t k : {3, 4}) {
      Eigen::Vector2d uv = in.camera.Project(in.poses[k].Inverse() * p_w);
      if (k == 4) uv.x() += 40.0;
      in.observations.push_back({k, id, uv, 0});
    }
  }
  JointProblemOptions options;
  JointProblem off = BuildJointProblem(in, options);
  EXPECT_EQ(off.gated_observations, 0);
  EXPECT_EQ(static_cast<int64_t>(off.visual_blocks.size()), before + 4);

  // Points of the toy seen only once: a free point then has no depth and is left out too.
  std::map<int32_t, int> seen;
  for (const auto& o : in.observations) ++seen[o.map_point];
  const int64_t single =
      std::count_if(seen.begin(), seen.end(), [](auto& s) { return s.second == 1; });
  options.visual_gate_chi2 = 5.991;
  JointProblem free_points = BuildJointProblem(in, options);
  // The bad observations go, and with them the two points, left with one observation each.
  EXPECT_EQ(free_points.gated_points, single + 2);
  EXPECT_EQ(free_points.gated_observations, single + 4);
  EXPECT_EQ(static_cast<int64_t>(free_points.visual_blocks.size()), before - single);

  options.optimize_map_points = false;  // a fixed point's single observation still holds a pose
  JointProblem fixed_points = BuildJointProblem(in, options);
  EXPECT_EQ(fixed_points.gated_points, 0);
  EXPECT_EQ(fixed_points.gated_observations, 2);
  EXPECT_EQ(static_cast<int64_t>(fixed_points.visual_blocks.size()), before + 2);

  const JointSolveResult result = SolveJointProblem(free_points, {});
  EXPECT_TRUE(result.usable);
  EXPECT_EQ(result.gated_observations, single + 4);
  EXPECT_EQ(result.gated_points, single + 2);
  EXPECT_EQ(result.before.visual.count, before - single);
}

TEST(JointProblem, PointsWithoutDepthInformationAreHeldConstant) {
  ToyRoad toy = MakeToyRoad(false);
  JointProblemInput& in = toy.input;
  // A far point seen by keyframes 3 and 4 (2 m apart, 0.2 deg parallax at 600 m) and a near
  // one (10 deg at 12 m), both observed exactly.
  const int32_t far = static_cast<int32_t>(in.map_points.size());
  in.map_points.push_back(in.poses[3] * Eigen::Vector3d(30.0, -5.0, 600.0));
  const int32_t near = far + 1;
  in.map_points.push_back(in.poses[3] * Eigen::Vector3d(2.0, -1.0, 12.0));
  for (int32_t id : {far, near}) {
    for (int64_t k : {3, 4}) {
      const Eigen::Vector3d p_k = in.poses[k].Inverse() * in.map_points[id];
      in.observations.push_back({k, id, in.camera.Project(p_k), 0});
    }
  }
  JointProblemOptions options;
  options.visual_gate_chi2 = 5.991;  // also leaves out the toy's single-observation points
  JointProblem all_free = BuildJointProblem(in, options);
  EXPECT_EQ(all_free.weak_points, 0);
  EXPECT_FALSE(all_free.problem->IsParameterBlockConstant(all_free.map_points[far].data()));

  // sigma of the far point along its ray: 600 m * (1 px / 707 px) / (2 m / 600 m) ~ 250 m.
  options.max_point_sigma_ratio = 0.1;
  JointProblem held = BuildJointProblem(in, options);
  EXPECT_TRUE(held.problem->IsParameterBlockConstant(held.map_points[far].data()));
  EXPECT_FALSE(held.problem->IsParameterBlockConstant(held.map_points[near].data()));
  EXPECT_GE(held.weak_points, 1);
  const JointSolveResult result = SolveJointProblem(held, {});
  EXPECT_TRUE(result.usable);
  EXPECT_EQ(result.weak_points, held.weak_points);
  EXPECT_EQ(result.map_points[far], in.map_points[far]);  // held constant

  // Dropped instead: the weak points' observations (the far point's two among them) leave the
  // problem, the near point stays free.
  options.drop_weak_points = true;
  JointProblem dropped = BuildJointProblem(in, options);
  EXPECT_EQ(dropped.weak_points, held.weak_points);
  const int64_t left_out =
      static_cast<int64_t>(held.visual_blocks.size() - dropped.visual_blocks.size());
  EXPECT_GE(left_out, 2 * held.weak_points);  // every weak point had >= 2 observations
  EXPECT_EQ(dropped.gated_observations, held.gated_observations + left_out);
  EXPECT_FALSE(dropped.problem->HasParameterBlock(dropped.map_points[far].data()));
  EXPECT_FALSE(dropped.problem->IsParameterBlockConstant(dropped.map_points[near].data()));
  options.drop_weak_points = false;

  // Dropped only from drop_weak_from on (the global problem's loop points): the far point is
  // the first such row, so it leaves the problem while the others are treated as before.
  in.drop_weak_from = static_cast<size_t>(far);
  JointProblem from_far = BuildJointProblem(in, options);
  EXPECT_FALSE(from_far.problem->HasParameterBlock(from_far.map_points[far].data()));
  EXPECT_FALSE(from_far.problem->IsParameterBlockConstant(from_far.map_points[near].data()));
  EXPECT_EQ(from_far.gated_observations, held.gated_observations + 2);
  in.drop_weak_from = static_cast<size_t>(-1);

  options.optimize_map_points = false;  // fixed map points: nothing to hold, nothing counted
  EXPECT_EQ(BuildJointProblem(in, options).weak_points, 0);
}

TEST(JointProblem, CostsBeforeAndAfterAreEvaluatedOnlyWhenAsked) {
  ToyRoad toy = MakeToyRoad(false);
  SolveOptions solve;
  const JointSolveResult both = OptimizeJoint(toy.input, {}, solve);
  EXPECT_GT(both.before.visual.count, 0);
  EXPECT_GT(both.after.visual.count, 0);
  solve.evaluate_before = false;
  solve.evaluate_after = false;
  const JointSolveResult none = OptimizeJoint(toy.input, {}, solve);
  // Not evaluated: the counts, and Ceres' total cost before and after the solve.
  EXPECT_EQ(none.before.visual.count, both.before.visual.count);
  EXPECT_EQ(none.after.imls.count, both.after.imls.count);
  EXPECT_EQ(none.before.visual.cost, 0.0);
  EXPECT_EQ(none.after.visual.rms, 0.0);
  EXPECT_NEAR(none.before.total, both.before.total, 1e-9 * both.before.total);
  EXPECT_NEAR(none.after.total, both.after.total, 1e-9 * both.before.total);
  EXPECT_LT(none.after.total, none.before.total);
  // Same solve either way.
  for (const auto& [id, pose] : both.poses)
    EXPECT_EQ(pose.translation(), none.poses.at(id).translation());
}

TEST(JointProblem, PoseOnlyProblemUsesSparseNormalCholesky) {
  ToyRoad toy = MakeToyRoad(true);
  toy.input.observations.clear();
  const JointSolveResult result = OptimizeJoint(toy.input, {}, {});
  EXPECT_EQ(result.linear_solver, "SPARSE_NORMAL_CHOLESKY");
  EXPECT_EQ(result.before.visual.count, 0);
  EXPECT_LE(result.after.total, result.before.total);
}

// A straight road at 1 m per frame whose only data term is an odometry that measures the motion
// along the road with 2 cm of white noise per frame (a registration that slides in a corridor)
// and the rest precisely. The motion term (a car's acceleration per frame, 9 mm along the road)
// takes most of that noise out of the frame-to-frame motion; without it the solution is the
// odometry.
TEST(JointProblem, MotionTermTakesFrameNoiseTheOtherTermsCannotSee) {
  constexpr int kFrames = 40;
  std::mt19937 rng(11);
  std::normal_distribution<double> along(0.0, 0.02);
  JointProblemInput in;
  in.camera = testing::KittiLikeCamera();
  std::map<int64_t, Rigid3d> truth;
  for (int k = 0; k < kFrames; ++k)
    truth[k] = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1.0 * k));
  for (int k = 0; k + 1 < kFrames; ++k) {
    RelativePoseConstraint c;
    c.i = k;
    c.j = k + 1;
    c.i_from_j = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1.0 + along(rng)));
    c.sigma_rad = Eigen::Vector3d::Constant(1e-4);
    c.sigma_m = Eigen::Vector3d(0.001, 0.001, 0.02);
    in.relative_poses.push_back(c);
  }
  // Start at the odometry, with both ends held at the truth (the road's length is known).
  in.poses[0] = truth[0];
  for (int k = 1; k < kFrames; ++k)
    in.poses[k] = in.poses[k - 1] * in.relative_poses[k - 1].i_from_j;
  in.poses[kFrames - 1] = truth[kFrames - 1];
  in.fixed = {0, kFrames - 1};
  auto frame_rms = [&](const std::map<int64_t, Rigid3d>& poses) {
    double sum = 0.0;
    for (int k = 0; k + 1 < kFrames; ++k) {
      const double step = poses.at(k + 1).translation().z() - poses.at(k).translation().z();
      sum += (step - 1.0) * (step - 1.0);
    }
    return std::sqrt(sum / (kFrames - 1));
  };
  const JointSolveResult without = OptimizeJoint(in, {}, {});
  for (int k = 1; k + 1 < kFrames; ++k) {
    MotionConstraint m;
    m.a = k - 1;
    m.b = k;
    m.c = k + 1;
    m.sigma_m = Eigen::Vector3d(0.0041, 0.0034, 0.0090);
    in.motion.push_back(m);
  }
  const JointSolveResult with = OptimizeJoint(in, {}, {});
  EXPECT_EQ(with.before.motion.count, kFrames - 2);
  EXPECT_EQ(without.before.motion.count, 0);
  const double rms_without = frame_rms(without.poses), rms_with = frame_rms(with.poses);
  EXPECT_GT(rms_without, 0.015);  // the odometry's noise
  EXPECT_LT(rms_with, 0.5 * rms_without) << rms_with << " vs " << rms_without;

  // A bad constraint is refused with a message.
  in.motion.push_back({0, 0, 1, 1.0, 1.0, Eigen::Vector3d::Constant(0.01)});
  EXPECT_THROW(OptimizeJoint(in, {}, {}), Error);
}

// The surface term in a corridor: walls and ground only, so the scans cannot tell how far the
// car moved, and the map points, free, can be placed at any scale with the cameras (a scene
// scaled about the first keyframe reprojects the same and keeps every wall and ground
// correspondence). The keyframes start 3 % too far apart, as an odometry that slid along the
// street. With the map points tied to the surface of their keyframes' own scans, the spacing
// comes out right; without, it stays where it started.
TEST(JointProblem, SurfaceTermFixesTheSpacingInACorridorTheScansCannotSee) {
  constexpr int kKeyframes = 16;
  constexpr double kSpacing = 2.0;
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> pixel_noise(0.0, 0.5), range_noise(0.0, 0.01);
  JointProblemInput in;
  in.camera = testing::KittiLikeCamera();
  std::map<int64_t, Rigid3d> truth;
  for (int k = 0; k < kKeyframes; ++k) {
    truth[k] = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, kSpacing * k));
    in.poses[k] =
        Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1.03 * kSpacing * k));
  }
  in.fixed = {0};
  std::vector<Eigen::Vector3d> true_points;
  for (int k = 0; k < kKeyframes; ++k) {
    for (int i = 0; i < 30; ++i) {  // wall points 8 m left and right, 6-30 m ahead of k
      const double side = i % 2 == 0 ? -1.0 : 1.0;
      const Eigen::Vector3d p_w(side * 8.0, -2.0 + 3.5 * u(rng),
                                kSpacing * k + 6.0 + 24.0 * u(rng));
      const int32_t id = static_cast<int32_t>(true_points.size());
      true_points.push_back(p_w);
      // Triangulated at the slid poses: the same rays, 1.03x the distances from keyframe 0.
      in.map_points.push_back(1.03 * p_w);
      for (int j = k; j < std::min(k + 3, kKeyframes); ++j) {
        const Eigen::Vector3d p_j = truth[j].Inverse() * p_w;
        if (p_j.z() < 1.0 || !in.camera.InImage(in.camera.Project(p_j))) continue;
        const Eigen::Vector2d noise(pixel_noise(rng), pixel_noise(rng));
        in.observations.push_back({j, id, in.camera.Project(p_j) + noise, 0});
        PointSurfaceConstraint c;
        c.keyframe = j;
        c.map_point = id;
        c.k_normal = Eigen::Vector3d(-side, 0, 0);
        c.k_p_y = p_j + range_noise(rng) * c.k_normal;
        in.point_surfaces.push_back(c);
      }
    }
    if (k == 0) continue;
    for (int i = 0; i < 30; ++i) {  // walls and ground between k and k - 1: no forward term
      ImlsCorrespondence l;
      l.n = k;
      l.c = k - 1;
      const double z = 3.0 + 20.0 * u(rng);
      if (i % 3 == 0) {
        l.c_p_y = Eigen::Vector3d(-6.0 + 12.0 * u(rng), 1.7, z);
        l.c_normal = -Eigen::Vector3d::UnitY();
      } else {
        const double side = i % 3 == 1 ? -1.0 : 1.0;
        l.c_p_y = Eigen::Vector3d(side * 8.0, -2.0 + 3.5 * u(rng), z);
        l.c_normal = Eigen::Vector3d(-side, 0, 0);
      }
      const Eigen::Vector3d sampled = l.c_p_y + range_noise(rng) * l.c_normal;
      l.p_x = truth[k].Inverse() * (truth[k - 1] * sampled);
      in.imls.push_back(l);
    }
  }
  const auto spacing_error = [&](const JointSolveResult& r) {
    double worst = 0.0;
    for (int k = 1; k < kKeyframes; ++k) {
      const double step = r.poses.at(k).translation().z() - r.poses.at(k - 1).translation().z();
      worst = std::max(worst, std::abs(step - kSpacing));
    }
    return worst;
  };
  const JointSolveResult with = OptimizeJoint(in, {}, {});
  EXPECT_GT(with.after.surface.count, 0);
  JointProblemInput without_input = in;
  without_input.point_surfaces.clear();
  const JointSolveResult without = OptimizeJoint(without_input, {}, {});
  EXPECT_EQ(without.after.surface.count, 0);
  ASSERT_TRUE(with.usable && without.usable);
  EXPECT_GT(spacing_error(without), 0.04) << "the corridor should leave the spacing undetermined";
  EXPECT_LT(spacing_error(with), 0.01) << spacing_error(with) << " m";
  // A constraint on a point the visual term does not hold is left out (it would be free along
  // the surface).
  JointProblemInput lone = in;
  lone.map_points.push_back(Eigen::Vector3d(8, 0, 10));
  lone.point_surfaces.push_back({1, static_cast<int32_t>(lone.map_points.size() - 1),
                                 Eigen::Vector3d(8, 0, 8), Eigen::Vector3d(-1, 0, 0)});
  // So is one of a keyframe that does not observe the point in the visual term (point 0 is
  // seen by keyframes 0-2 only).
  lone.point_surfaces.push_back({10, 0, Eigen::Vector3d(8, 0, 8), Eigen::Vector3d(-1, 0, 0)});
  JointProblem built = BuildJointProblem(lone, {});
  EXPECT_EQ(built.surface_blocks.size(), in.point_surfaces.size());
  // Points held constant get none: they would pull the poses to where they were put.
  JointProblemOptions held;
  held.optimize_map_points = false;
  EXPECT_TRUE(BuildJointProblem(in, held).surface_blocks.empty());

  // Solved as global problems are (SPARSE_SCHUR), the same result; every residual block on a
  // map point has two rows (the surface block pads its one with a zero), so Ceres eliminates the
  // points with its code specialised for 2 x 3 x 6 blocks, not the generic dynamic-size one.
  SolveOptions sparse;
  sparse.dense_schur_max_blocks = 0;
  const JointSolveResult global = OptimizeJoint(in, {}, sparse);
  ASSERT_TRUE(global.usable);
  EXPECT_EQ(global.linear_solver, "SPARSE_SCHUR");
  EXPECT_EQ(global.schur_structure, "2,3,6");
  EXPECT_LT(spacing_error(global), 0.01) << spacing_error(global) << " m";
}

}  // namespace
}  // namespace jvl::optim
