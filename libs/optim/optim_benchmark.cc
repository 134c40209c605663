// Cost evaluation (autodiff vs analytic Jacobians) and joint solves on the synthetic road.
// Build with -DJVL_BUILD_BENCHMARKS=ON; run build/bin/optim_benchmark.
#include <benchmark/benchmark.h>

#include <memory>

#include "optim/analytic_costs.h"
#include "optim/cost_functions.h"
#include "optim/toy_road.h"

namespace jvl::optim {
namespace {

// Evaluates residuals and all Jacobians of `cost` at `params`.
void EvaluateLoop(benchmark::State& state, const ceres::CostFunction& cost,
                  std::vector<double*> params) {
  std::vector<double> residuals(cost.num_residuals());
  std::vector<std::vector<double>> jac;
  std::vector<double*> jac_ptrs;
  for (int32_t size : cost.parameter_block_sizes()) {
    jac.emplace_back(static_cast<size_t>(size * cost.num_residuals()));
  }
  for (auto& j : jac) jac_ptrs.push_back(j.data());
  for (auto _ : state) {
    cost.Evaluate(params.data(), residuals.data(), jac_ptrs.data());
    benchmark::DoNotOptimize(jac_ptrs[0][0]);
  }
}

void BM_Imls(benchmark::State& state) {
  std::mt19937 rng(1);
  PoseBlock n = ToPoseBlock(testing::RandomPose(rng, 0.3, 5));
  PoseBlock c = ToPoseBlock(testing::RandomPose(rng, 0.3, 5));
  const Eigen::Vector3d p_x(1, 2, 10), p_y(1.1, 2, 9),
      normal = Eigen::Vector3d(0, -1, 0.1).normalized();
  std::unique_ptr<ceres::CostFunction> cost(
      state.range(0)
          ? static_cast<ceres::CostFunction*>(new PointToImlsAnalyticCost(p_x, p_y, normal, 20.0))
          : PointToImlsCost::Create(p_x, p_y, normal, 20.0));
  EvaluateLoop(state, *cost, {n.data(), c.data()});
}
BENCHMARK(BM_Imls)->ArgName("analytic")->Arg(0)->Arg(1);

void BM_Direction(benchmark::State& state) {
  std::mt19937 rng(2);
  PoseBlock pose = ToPoseBlock(testing::RandomPose(rng, 0.3, 5));
  const PinholeCamera camera = testing::KittiLikeCamera();
  const Eigen::Vector3d d_w(0.1, 0, 1);
  std::unique_ptr<ceres::CostFunction> cost(
      state.range(0) ? static_cast<ceres::CostFunction*>(new DirectionProjectionAnalyticCost(
                           camera, {600, 180}, d_w, Eigen::Vector2d(1.0, 1.0), 0.05))
                     : DirectionProjectionCost::Create(camera, {600, 180}, d_w,
                                                       Eigen::Vector2d(1.0, 1.0), 0.05));
  EvaluateLoop(state, *cost, {pose.data()});
}
BENCHMARK(BM_Direction)->ArgName("analytic")->Arg(0)->Arg(1);

void BM_Visual(benchmark::State& state) {
  PoseBlock pose = ToPoseBlock(Rigid3d());
  std::array<double, 3> point = {1, -0.5, 12};
  std::unique_ptr<ceres::CostFunction> cost(
      VisualReprojectionCost::Create(testing::KittiLikeCamera(), {650, 160}, 1.0));
  EvaluateLoop(state, *cost, {pose.data(), point.data()});
}
BENCHMARK(BM_Visual);

// Full joint solve of the synthetic road (all three residual types), 0.03 deg yaw drift per
// keyframe (9 deg over 300 keyframes).
void BM_SolveToyRoad(benchmark::State& state) {
  const testing::ToyRoad toy =
      testing::MakeToyRoad(true, static_cast<int>(state.range(0)), 0.03 * M_PI / 180.0);
  JointProblemOptions options;
  options.analytic_jacobians = state.range(1) != 0;
  SolveOptions solve;
  solve.threads = static_cast<int>(state.range(2));
  int64_t residuals = 0;
  for (auto _ : state) {
    const JointSolveResult r = OptimizeJoint(toy.input, options, solve);
    residuals = r.before.visual.count + r.before.imls.count + r.before.direction.count;
    benchmark::DoNotOptimize(r.after.total);
  }
  state.counters["residuals"] = static_cast<double>(residuals);
}
BENCHMARK(BM_SolveToyRoad)
    ->ArgNames({"keyframes", "analytic", "threads"})
    ->Args({300, 0, 1})
    ->Args({300, 1, 1})
    ->Args({300, 1, 2})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace jvl::optim

BENCHMARK_MAIN();
