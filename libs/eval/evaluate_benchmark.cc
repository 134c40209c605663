// Benchmark: every metric (association, sim3 alignment, APE, RPE, KITTI segments) on a
// 4541-pose trajectory, the length of KITTI sequence 00. Budget: <= 2 s (ARCHITECTURE.md).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <random>

#include "eval/evaluate.h"
#include "eval/report.h"

namespace jvl::eval {
namespace {

void MakeTrajectories(int n, PoseSeries* gt, PoseSeries* est) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, 1);
  Eigen::Matrix4d g = Eigen::Matrix4d::Identity(), e = g;
  for (int f = 0; f < n; ++f) {
    gt->frames.push_back(f);
    gt->poses.push_back(g);
    est->frames.push_back(f);
    est->poses.push_back(e);
    Eigen::Matrix4d step = Eigen::Matrix4d::Identity();
    step.topLeftCorner<3, 3>() =
        Eigen::AngleAxisd(0.02 * std::sin(f / 60.0), Eigen::Vector3d::UnitY()).toRotationMatrix();
    step(2, 3) = 1.2;
    Eigen::Matrix4d drift = Eigen::Matrix4d::Identity();
    drift.topLeftCorner<3, 3>() =
        Eigen::AngleAxisd(1e-3 * noise(rng), Eigen::Vector3d::UnitY()).toRotationMatrix();
    drift(0, 3) = 0.01 * noise(rng);
    g = g * step;
    e = e * step * drift;
  }
}

void BM_EvaluateAllMetrics(benchmark::State& state) {
  PoseSeries gt, est;
  MakeTrajectories(static_cast<int>(state.range(0)), &gt, &est);
  EvalOptions options;
  options.alignment = Alignment::kSim3;
  options.origin_first = true;
  for (auto _ : state) {
    const SequenceEval r = EvaluateSequence(gt, est, options, "00");
    const EstimateEval e = CombineSequences("est", {r}, options.kitti);
    benchmark::DoNotOptimize(ReportToJson({e}, options).size());
  }
}
BENCHMARK(BM_EvaluateAllMetrics)->Arg(4541)->Unit(benchmark::kMillisecond)->Repetitions(5);

}  // namespace
}  // namespace jvl::eval

BENCHMARK_MAIN();
