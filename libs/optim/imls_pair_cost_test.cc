#include "optim/imls_pair_cost.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "core/check.h"
#include "optim/analytic_costs.h"
#include "optim/joint_problem.h"
#include "optim/test_util.h"
#include "optim/toy_road.h"

namespace jvl::optim {
namespace {

using testing::LocalJacobianError;
using testing::RandomPose;

struct Correspondence {
  Eigen::Vector3d p_x, c_p_y, c_normal;
};

// Correspondences as local mapping produces them: p_x up to ~60 m from keyframe n, c_p_y near
// its image in c (up to `off_surface` m off the surface), unit normals.
std::vector<Correspondence> RandomPair(std::mt19937& rng, const Rigid3d& world_from_n,
                                       const Rigid3d& world_from_c, int count,
                                       double off_surface = 0.05) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Correspondence> out;
  for (int i = 0; i < count; ++i) {
    Correspondence l;
    l.p_x = Eigen::Vector3d(60 * u(rng), 3 * u(rng), 40 + 20 * u(rng));
    l.c_normal = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    l.c_p_y = world_from_c.Inverse() * (world_from_n * l.p_x) + off_surface * u(rng) * l.c_normal +
              Eigen::Vector3d(u(rng), u(rng), u(rng)).cross(l.c_normal) * 0.3;
    out.push_back(l);
  }
  return out;
}

struct Normal {
  Eigen::Matrix<double, 14, 14> jtj = Eigen::Matrix<double, 14, 14>::Zero();
  Eigen::Matrix<double, 14, 1> jtr = Eigen::Matrix<double, 14, 1>::Zero();
  double cost = 0.0;  // sum of squared residuals
};

// Adds r, J (ambient, both blocks) of `cost` at `params` to the normal equations.
void Accumulate(const ceres::CostFunction& cost, double* const* params, Normal* n) {
  const int m = cost.num_residuals();
  std::vector<double> r(m), j0(7 * m), j1(7 * m);
  double* jac[2] = {j0.data(), j1.data()};
  ASSERT_TRUE(cost.Evaluate(params, r.data(), jac));
  Eigen::MatrixXd j(m, 14);
  for (int row = 0; row < m; ++row)
    for (int c = 0; c < 7; ++c) {
      j(row, c) = j0[row * 7 + c];
      j(row, 7 + c) = j1[row * 7 + c];
    }
  const Eigen::Map<Eigen::VectorXd> rv(r.data(), m);
  n->jtj += j.transpose() * j;
  n->jtr += j.transpose() * rv;
  n->cost += rv.squaredNorm();
}

// The pair block reproduces the cost, gradient and Gauss-Newton matrix of the individual
// residuals, at the linearisation pose and away from it.
TEST(ImlsPairCost, SameCostGradientAndGaussNewtonMatrixAsTheIndividualResiduals) {
  std::mt19937 rng(7);
  const Rigid3d world_from_n = RandomPose(rng, 0.5, 50.0);
  const Rigid3d world_from_c = world_from_n * RandomPose(rng, 0.05, 8.0);
  const auto pair = RandomPair(rng, world_from_n, world_from_c, 400);
  const double sqrt_info = 1.0 / 0.05;
  ImlsPairAccumulator acc;
  for (const auto& l : pair) acc.Add(l.p_x, l.c_p_y, l.c_normal);
  const ImlsPairCost block(acc, sqrt_info);
  EXPECT_EQ(acc.count(), 400);
  EXPECT_EQ(block.rank(), 13);
  for (int trial = 0; trial < 4; ++trial) {
    // trial 0: the generating poses; then perturbed by up to 3 deg / 1 m.
    Rigid3d n_pose = world_from_n, c_pose = world_from_c;
    if (trial > 0) {
      n_pose = n_pose * RandomPose(rng, 0.05, 1.0);
      c_pose = c_pose * RandomPose(rng, 0.05, 1.0);
    }
    PoseBlock pn = ToPoseBlock(n_pose), pc = ToPoseBlock(c_pose);
    double* params[2] = {pn.data(), pc.data()};
    Normal individual, compressed;
    for (const auto& l : pair)
      Accumulate(PointToImlsAnalyticCost(l.p_x, l.c_p_y, l.c_normal, sqrt_info), params,
                 &individual);
    Accumulate(block, params, &compressed);
    SCOPED_TRACE("trial " + std::to_string(trial));
    EXPECT_NEAR(compressed.cost, individual.cost, 1e-9 * individual.cost);
    const double g = individual.jtr.norm(), h = individual.jtj.norm();
    EXPECT_LT((compressed.jtr - individual.jtr).norm(), 1e-8 * g) << g;
    EXPECT_LT((compressed.jtj - individual.jtj).norm(), 1e-9 * h) << h;
  }
}

TEST(ImlsPairCost, JacobianMatchesCentralDifferencesOnTheManifold) {
  std::mt19937 rng(11);
  const Rigid3d world_from_n = RandomPose(rng, 0.5, 20.0);
  const Rigid3d world_from_c = world_from_n * RandomPose(rng, 0.1, 5.0);
  ImlsPairAccumulator acc;
  for (const auto& l : RandomPair(rng, world_from_n, world_from_c, 30))
    acc.Add(l.p_x, l.c_p_y, l.c_normal);
  const ImlsPairCost block(acc, 20.0);
  PoseBlock pn = ToPoseBlock(world_from_n * RandomPose(rng, 0.02, 0.5));
  PoseBlock pc = ToPoseBlock(world_from_c);
  EXPECT_LT(LocalJacobianError(block, {true, true}, {pn.data(), pc.data()}), 1e-5);
}

// Fewer correspondences than the 13 unknowns of x: one residual row per correspondence (the
// rank of H), and still the same cost.
TEST(ImlsPairCost, FewCorrespondencesGiveOneRowEach) {
  std::mt19937 rng(3);
  const Rigid3d world_from_n = RandomPose(rng, 0.3, 10.0);
  const Rigid3d world_from_c = world_from_n * RandomPose(rng, 0.05, 2.0);
  const auto pair = RandomPair(rng, world_from_n, world_from_c, 4);
  ImlsPairAccumulator acc;
  for (const auto& l : pair) acc.Add(l.p_x, l.c_p_y, l.c_normal);
  const ImlsPairCost block(acc, 20.0);
  EXPECT_EQ(block.rank(), 4);
  PoseBlock pn = ToPoseBlock(world_from_n * RandomPose(rng, 0.02, 0.3)),
            pc = ToPoseBlock(world_from_c);
  double* params[2] = {pn.data(), pc.data()};
  Normal individual, compressed;
  for (const auto& l : pair)
    Accumulate(PointToImlsAnalyticCost(l.p_x, l.c_p_y, l.c_normal, 20.0), params, &individual);
  Accumulate(block, params, &compressed);
  EXPECT_NEAR(compressed.cost, individual.cost, 1e-8 * individual.cost);
}

// The assembled problem: one block per keyframe pair, the same statistics and the same solution
// as one block per correspondence; with a Huber kernel on e_L nothing is compressed.
TEST(ImlsPairCost, JointProblemWithPairBlocksReachesTheSameSolution) {
  const testing::ToyRoad toy = testing::MakeToyRoad(true);
  JointProblemOptions pairs, single;
  single.compress_imls = false;
  const JointProblem built_pairs = BuildJointProblem(toy.input, pairs);
  const JointProblem built_single = BuildJointProblem(toy.input, single);
  EXPECT_EQ(built_single.imls_blocks.size(), toy.input.imls.size());
  EXPECT_LT(built_pairs.imls_blocks.size(), built_single.imls_blocks.size() / 5);
  int64_t represented = 0;
  for (int64_t c : built_pairs.imls_block_counts) represented += c;
  EXPECT_EQ(represented, static_cast<int64_t>(toy.input.imls.size()));

  const JointSolveResult a = OptimizeJoint(toy.input, pairs, {});
  const JointSolveResult b = OptimizeJoint(toy.input, single, {});
  EXPECT_EQ(a.before.imls.count, b.before.imls.count);
  EXPECT_NEAR(a.before.imls.cost, b.before.imls.cost, 1e-9 * b.before.imls.cost);
  EXPECT_NEAR(a.before.imls.rms, b.before.imls.rms, 1e-9 * b.before.imls.rms);
  EXPECT_NEAR(a.after.total, b.after.total, 1e-6 * b.after.total);
  EXPECT_LT(testing::MaxPoseDifference(a.poses, b.poses), 1e-7);

  // The first half summed beforehand (as global_opt keeps the saved set L), merged with the rest.
  JointProblemInput split = toy.input;
  const size_t half = split.imls.size() / 2;
  split.imls_pairs = AggregateImls({split.imls.begin(), split.imls.begin() + half});
  split.imls.erase(split.imls.begin(), split.imls.begin() + half);
  EXPECT_EQ(CountImls(split), static_cast<int64_t>(toy.input.imls.size()));
  const JointSolveResult c = OptimizeJoint(split, pairs, {});
  EXPECT_EQ(c.weights.beta, a.weights.beta);
  EXPECT_NEAR(c.before.imls.cost, b.before.imls.cost, 1e-9 * b.before.imls.cost);
  EXPECT_LT(testing::MaxPoseDifference(c.poses, b.poses), 1e-7);

  JointProblemOptions huber;
  huber.imls_huber = 2.0;
  EXPECT_EQ(BuildJointProblem(toy.input, huber).imls_blocks.size(), toy.input.imls.size());
  EXPECT_THROW(BuildJointProblem(split, huber), Error);
}

// Six keyframes k = 0..5 in a chain and the 400 correspondences of each pair (k, k - 1), with
// points up to 12 cm off the surface for k in `rough`, 2 cm for the others.
JointProblemInput PairChain(unsigned seed, const std::set<int64_t>& rough) {
  std::mt19937 rng(seed);
  JointProblemInput input;
  input.camera = testing::MakeToyRoad(false).input.camera;
  Rigid3d pose = RandomPose(rng, 0.1, 1.0);
  for (int64_t k = 0; k < 6; ++k) {
    input.poses[k] = pose;
    pose = pose * RandomPose(rng, 0.02, 1.0);
  }
  for (int64_t k = 1; k < 6; ++k) {
    const double off = rough.count(k) ? 0.12 : 0.02;
    for (const auto& l : RandomPair(rng, input.poses[k], input.poses[k - 1], 400, off))
      input.imls.push_back({k, k - 1, l.p_x, l.c_p_y, l.c_normal});
  }
  return input;
}

// The cost of each e_L block of `jp`, in block order.
std::vector<double> ImlsBlockCosts(const JointProblem& jp) {
  std::vector<double> costs(jp.imls_blocks.size());
  for (size_t i = 0; i < costs.size(); ++i) {
    EXPECT_TRUE(
        jp.problem->EvaluateResidualBlock(jp.imls_blocks[i], false, &costs[i], nullptr, nullptr));
  }
  return costs;
}

// imls_pair_noise_max: a pair whose residuals are f times the median pair's gets the sigma x
// min(f, max), i.e. its block cost / min(f, max)^2; the other pairs keep theirs. Off (<= 1),
// every block is as before.
TEST(ImlsPairCost, PairNoiseRaisesTheSigmaOfRoughPairsOnly) {
  // Pairs (k, k - 1): four with points up to 2 cm off the surface, one rough (12 cm: 6x).
  const JointProblemInput input = PairChain(5, {3});
  JointProblemOptions off, on;
  on.imls_pair_noise_max = 3.0;
  off.beta = on.beta = 1.0;
  JointProblem a = BuildJointProblem(input, off);
  JointProblem b = BuildJointProblem(input, on);
  ASSERT_EQ(a.imls_blocks.size(), 5u);
  ASSERT_EQ(b.imls_blocks.size(), 5u);
  // Each pair's RMS from its block cost without the option: cost = 0.5 sum r^2 / sigma^2.
  const std::vector<double> cost_a = ImlsBlockCosts(a), cost_b = ImlsBlockCosts(b);
  std::vector<double> rms(5);
  for (size_t i = 0; i < 5; ++i) rms[i] = std::sqrt(2.0 * cost_a[i] / 400.0) * off.imls_sigma_m;
  std::vector<double> sorted = rms;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[2];
  // Uniform noise on [-s, s] has RMS s / sqrt(3): about 11.5 mm for the clean pairs.
  EXPECT_NEAR(b.imls_pair_median_rms_m, median, 1e-8 * median);  // LDL^T vs x^T H x rounding
  EXPECT_NEAR(median, 0.02 / std::sqrt(3.0), 0.002);
  EXPECT_GT(rms[2] / median, 4.0);  // pair (3, 2): its sigma is capped at 3x
  EXPECT_EQ(a.imls_pairs_inflated, 0);
  EXPECT_EQ(b.imls_pairs_inflated, 2);  // the rough pair and the clean one above the median
  for (size_t i = 0; i < 5; ++i) {
    const double f = std::clamp(rms[i] / median, 1.0, 3.0);
    EXPECT_NEAR(cost_b[i], cost_a[i] / (f * f), 1e-7 * cost_a[i]) << "pair " << i;
  }
  EXPECT_NEAR(cost_b[2], cost_a[2] / 9.0, 1e-7 * cost_a[2]);
}

// The gauge's pairs keep one sigma whatever their residuals: with the free poses moved as a
// whole away from the gauge, only those pairs are rough, and widening them would loosen the
// gauge. The gauge is the fixed set, or the first keyframe when none is given.
TEST(ImlsPairCost, PairNoiseLeavesTheGaugesPairsAtOneSigma) {
  // Pairs (k, k - 1): (1, 0) and (4, 3) rough (12 cm), the other three clean (2 cm).
  const JointProblemInput input = PairChain(7, {1, 4});
  JointProblemOptions off, on;
  on.imls_pair_noise_max = 3.0;
  off.beta = on.beta = 1.0;
  JointProblemInput fixed_three = input;
  fixed_three.fixed = {3};
  const JointProblem a = BuildJointProblem(input, off);
  const JointProblem first = BuildJointProblem(input, on);        // gauge: keyframe 0
  const JointProblem three = BuildJointProblem(fixed_three, on);  // gauge: keyframe 3
  ASSERT_EQ(a.imls_blocks.size(), 5u);
  const std::vector<double> cost_a = ImlsBlockCosts(a), cost_first = ImlsBlockCosts(first),
                            cost_three = ImlsBlockCosts(three);
  ASSERT_EQ(cost_first.size(), 5u);
  ASSERT_EQ(cost_three.size(), 5u);
  // Block i is pair (i + 1, i). Keyframe 0's pair (1, 0) is rough but keeps its sigma; the rough
  // pair (4, 3) away from the gauge is widened to the cap (factor 3, cost / 9).
  EXPECT_NEAR(cost_first[0], cost_a[0], 1e-9 * cost_a[0]);
  EXPECT_NEAR(cost_first[3], cost_a[3] / 9.0, 1e-7 * cost_a[3]);
  // With keyframe 3 fixed, its pairs (3, 2) and (4, 3) keep their sigma, and (1, 0) is widened.
  EXPECT_NEAR(cost_three[2], cost_a[2], 1e-9 * cost_a[2]);
  EXPECT_NEAR(cost_three[3], cost_a[3], 1e-9 * cost_a[3]);
  EXPECT_NEAR(cost_three[0], cost_a[0] / 9.0, 1e-7 * cost_a[0]);
  EXPECT_EQ(first.fixed, std::set<int64_t>{0});
  EXPECT_EQ(three.fixed, std::set<int64_t>{3});
}

}  // namespace
}  // namespace jvl::optim
