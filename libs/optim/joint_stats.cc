// Cost breakdown and the Levenberg-Marquardt solve of a built JointProblem.
#include <ceres/iteration_callback.h>
#include <ceres/solver.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <string>
#include <utility>

#include "core/check.h"
#include "core/timer.h"
#include "optim/joint_problem.h"
#include "optim/schur_lm.h"

namespace jvl::optim {
namespace {

// `count`: residuals represented by the blocks (a compressed IMLS block stands for all the
// correspondences of its keyframe pair and its squared norm is their sum of squares).
ResidualStats Evaluate(ceres::Problem& problem, const std::vector<ceres::ResidualBlockId>& ids,
                       int64_t count) {
  ResidualStats stats;
  stats.count = count;
  if (ids.empty()) return stats;  // an empty list would mean "all residual blocks" to Ceres
  ceres::Problem::EvaluateOptions options;
  options.residual_blocks = ids;
  options.num_threads = 1;  // a fixed order of the sums (see MakeSolverOptions)
  options.apply_loss_function = true;
  problem.Evaluate(options, &stats.cost, nullptr, nullptr, nullptr);
  // Whitened residuals without weight or robust kernel: comparable across weight settings.
  options.apply_loss_function = false;
  std::vector<double> residuals;
  problem.Evaluate(options, nullptr, &residuals, nullptr, nullptr);
  double sum = 0.0;
  for (double r : residuals) sum += r * r;
  stats.rms = std::sqrt(sum / static_cast<double>(count));
  return stats;
}

ceres::Solver::Options MakeSolverOptions(JointProblem& jp, const SolveOptions& options) {
  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;  // as in the paper
  so.max_num_iterations = options.max_iterations;
  // One thread, whatever options.threads says: Ceres' multi-threaded reductions (the cost, the
  // gradient, the Schur complement) add up in the order its threads finish, so results would
  // differ in the last bits from run to run, and those bits can flip a step's acceptance or the
  // convergence test. On one thread the result does not depend on the thread count at all
  // (measured on the demo's local_map: 16 % slower than with 2 Ceres threads).
  so.num_threads = 1;
  so.function_tolerance = options.function_tolerance;
  so.gradient_tolerance = options.gradient_tolerance;
  so.parameter_tolerance = options.parameter_tolerance;
  so.max_solver_time_in_seconds = options.max_time_s;
  so.minimizer_progress_to_stdout = options.log_progress;
  so.logging_type = options.log_progress ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  // Debian's Ceres 2.1 is built with SuiteSparse (CHOLMOD) and Eigen sparse; prefer CHOLMOD.
  so.sparse_linear_algebra_library_type =
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ? ceres::SUITE_SPARSE
                                                                            : ceres::EIGEN_SPARSE;
  if (!jp.has_free_map_points) {
    so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    return so;
  }
  // Bundle-adjustment structure: eliminate the map points first (Schur complement). Ceres keeps
  // the blocks of one group in address order; the poses live in map nodes whose addresses
  // depend on the process's heap history, so with one group for all poses the Schur complement
  // was assembled in a different order from run to run and results differed in the last bits.
  // One group per pose, in keyframe-id order, makes the order that of the ids (the points are
  // one contiguous array, so their address order is their index order).
  int free_blocks = 0;
  for (auto& [id, block] : jp.poses) {
    free_blocks += jp.problem->IsParameterBlockConstant(block.data()) ? 0 : 1;
  }
  free_blocks += static_cast<int>(jp.free_directions.size());
  so.linear_solver_type =
      free_blocks <= options.dense_schur_max_blocks ? ceres::DENSE_SCHUR : ceres::SPARSE_SCHUR;
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (auto& point : jp.map_points) {
    if (jp.problem->HasParameterBlock(point.data())) ordering->AddElementToGroup(point.data(), 0);
  }
  int group = 1;
  for (auto& [id, block] : jp.poses) ordering->AddElementToGroup(block.data(), group++);
  for (auto& d : jp.free_directions) ordering->AddElementToGroup(d.data(), group++);
  so.linear_solver_ordering = ordering;
  return so;
}

class ProgressLog : public ceres::IterationCallback {
 public:
  explicit ProgressLog(std::string label) : label_(std::move(label)) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    spdlog::info("{} iteration {}: cost {:.6g}{}, {:.1f} s", label_, s.iteration, s.cost,
                 s.step_is_successful || s.iteration == 0 ? "" : " (step rejected)",
                 s.cumulative_time_in_seconds);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  std::string label_;
};

}  // namespace

void SolveOptions::Check() const {
  JVL_CHECK(max_iterations > 0, "max_iterations must be positive (got " << max_iterations << ")");
  JVL_CHECK(threads >= 1, "threads must be >= 1 (got " << threads << ")");
  JVL_CHECK(function_tolerance >= 0 && gradient_tolerance >= 0 && parameter_tolerance >= 0,
            "solver tolerances must be non-negative");
  JVL_CHECK(max_time_s > 0, "max_time_s must be positive");
  JVL_CHECK(dense_schur_max_blocks >= 0,
            "dense_schur_max_blocks must be >= 0 (got " << dense_schur_max_blocks << ")");
}

namespace {

// The residual counts of each term without evaluating anything; `total` is left to the caller.
JointCostBreakdown CountResiduals(const JointProblem& jp) {
  JointCostBreakdown b;
  b.visual.count = static_cast<int64_t>(jp.visual_blocks.size());
  for (int64_t c : jp.imls_block_counts) b.imls.count += c;
  b.direction.count = static_cast<int64_t>(jp.direction_blocks.size());
  b.relative.count = static_cast<int64_t>(jp.relative_blocks.size());
  b.motion.count = static_cast<int64_t>(jp.motion_blocks.size());
  b.surface.count = static_cast<int64_t>(jp.surface_blocks.size());
  return b;
}

}  // namespace

JointCostBreakdown EvaluateJointCost(JointProblem& jp) {
  JointCostBreakdown b = CountResiduals(jp);
  b.visual = Evaluate(*jp.problem, jp.visual_blocks, b.visual.count);
  b.imls = Evaluate(*jp.problem, jp.imls_blocks, b.imls.count);
  b.direction = Evaluate(*jp.problem, jp.direction_blocks, b.direction.count);
  b.relative = Evaluate(*jp.problem, jp.relative_blocks, b.relative.count);
  b.motion = Evaluate(*jp.problem, jp.motion_blocks, b.motion.count);
  b.surface = Evaluate(*jp.problem, jp.surface_blocks, b.surface.count);
  b.total = b.visual.cost + b.imls.cost + b.direction.cost + b.relative.cost + b.motion.cost +
            b.surface.cost;
  return b;
}

JointSolveResult SolveJointProblem(JointProblem& jp, const SolveOptions& options) {
  options.Check();
  JVL_CHECK(jp.problem != nullptr, "joint problem was not built");
  const Timer timer;
  JointSolveResult result;
  result.weights = jp.weights;
  result.imls_blocks = static_cast<int64_t>(jp.imls_blocks.size());
  result.dropped_observations = jp.dropped_observations;
  result.gated_observations = jp.gated_observations;
  result.gated_points = jp.gated_points;
  result.weak_points = jp.weak_points;
  result.imls_pair_median_rms_m = jp.imls_pair_median_rms_m;
  result.imls_pairs_inflated = jp.imls_pairs_inflated;
  Timer phase;
  result.before = options.evaluate_before ? EvaluateJointCost(jp) : CountResiduals(jp);
  const double before_s = phase.ElapsedSeconds();
  ceres::Solver::Options so = MakeSolverOptions(jp, options);
  ProgressLog progress(options.progress_label);
  if (!options.progress_label.empty()) so.callbacks.push_back(&progress);
  ceres::Solver::Summary summary;
  std::vector<double*> points;
  if (options.schur_lm && so.linear_solver_type == ceres::DENSE_SCHUR) {
    for (auto& point : jp.map_points) {
      if (jp.problem->HasParameterBlock(point.data())) points.push_back(point.data());
    }
    if (!SchurLmApplies(*jp.problem, points, kPoseTangentSize * options.dense_schur_max_blocks))
      points.clear();
  }
  if (!points.empty()) {
    SchurLmOptions lm;
    lm.max_iterations = options.max_iterations;
    lm.function_tolerance = options.function_tolerance;
    lm.gradient_tolerance = options.gradient_tolerance;
    lm.parameter_tolerance = options.parameter_tolerance;
    lm.max_time_s = options.max_time_s;
    lm.progress_label = options.progress_label;
    const SchurLmSummary s = SolveSchurLm(*jp.problem, points, lm);
    result.iterations = s.iterations;
    result.usable = s.usable;
    result.termination = s.report;
    if (!options.evaluate_before) result.before.total = s.initial_cost;
    summary.final_cost = s.final_cost;
    result.linear_solver = "SCHUR_LM";
  } else if (jp.problem->NumResidualBlocks() > 0) {
    ceres::Solve(so, jp.problem.get(), &summary);
    result.iterations = static_cast<int>(summary.iterations.size()) - 1;
    result.usable = summary.IsSolutionUsable();
    result.termination = summary.BriefReport();
    result.schur_structure = summary.schur_structure_used;
    if (!options.evaluate_before) result.before.total = summary.initial_cost;
  } else {
    result.usable = true;
    result.termination = "no residuals";
  }
  if (points.empty()) result.linear_solver = ceres::LinearSolverTypeToString(so.linear_solver_type);
  phase.Reset();
  if (options.evaluate_after || !result.usable) {
    result.after = EvaluateJointCost(jp);
  } else {
    result.after = CountResiduals(jp);
    result.after.total = jp.problem->NumResidualBlocks() > 0 ? summary.final_cost : 0.0;
  }
  spdlog::debug(
      "joint solve: cost by term {:.1f} s before, {:.1f} s after; Ceres preprocessor {:.1f} s, "
      "minimizer {:.1f} s (Jacobians {:.1f} s, residuals {:.1f} s, linear solver {:.1f} s), "
      "postprocessor {:.1f} s; Schur structure {}",
      before_s, phase.ElapsedSeconds(), summary.preprocessor_time_in_seconds,
      summary.minimizer_time_in_seconds, summary.jacobian_evaluation_time_in_seconds,
      summary.residual_evaluation_time_in_seconds, summary.linear_solver_time_in_seconds,
      summary.postprocessor_time_in_seconds,
      result.schur_structure.empty() ? "-" : result.schur_structure);
  for (const auto& [id, block] : jp.poses) result.poses[id] = FromPoseBlock(block);
  result.map_points.reserve(jp.map_points.size());
  for (const auto& p : jp.map_points) result.map_points.emplace_back(p[0], p[1], p[2]);
  for (const auto& d : jp.free_directions) result.free_directions.emplace_back(d[0], d[1], d[2]);
  result.time_s = timer.ElapsedSeconds();
  return result;
}

JointSolveResult OptimizeJoint(const JointProblemInput& input, const JointProblemOptions& options,
                               const SolveOptions& solve_options) {
  const Timer build;
  JointProblem jp = BuildJointProblem(input, options);
  spdlog::debug("joint problem built in {:.1f} s", build.ElapsedSeconds());
  return SolveJointProblem(jp, solve_options);
}

}  // namespace jvl::optim
