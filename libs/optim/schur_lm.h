// Levenberg-Marquardt for small bundle-adjustment problems: map points eliminated, the reduced
// camera system kept dense.
//
// A local window of Sec. 4.2 (about 20 free keyframes, thousands of map points, 5 iterations at
// the median) is solved once per keyframe, so what Ceres does around the iterations counts:
// preparing a program for every solve, its general block-sparse bookkeeping and a lock per cell
// of the Schur complement. SolveSchurLm runs the same trust-region Levenberg-Marquardt as Ceres'
// (the step control, Jacobi scaling and stopping rules of Ceres' Solver::Options defaults; see
// docs/optimization.md "Local solver") on a built ceres::Problem, evaluating its cost functions,
// loss functions and manifolds as Ceres does, and eliminating the given point blocks itself:
//
//   (J^T J + D^2) dx = -J^T f,   D^2 = diag(J^T J) / radius,   J scaled by 1 / (1 + |column|)
//   points eliminated:  (U - W V^-1 W^T) dc = -g_c + W V^-1 g_p,   dp = V^-1 (-g_p - W^T dc)
//
// The solver is single-threaded and sums in a fixed order (residual blocks in insertion order),
// so the result does not depend on the machine's thread count.
#pragma once

#include <ceres/problem.h>

#include <string>
#include <vector>

namespace jvl::optim {

struct SchurLmOptions {
  int max_iterations = 100;
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
  double max_time_s = 1e9;     // wall-clock limit (tests only: makes results machine-dependent)
  std::string progress_label;  // non-empty: one info log line per iteration
};

struct SchurLmSummary {
  bool usable = false;     // converged, or stopped by the iteration / time limit
  bool converged = false;  // function, parameter or gradient tolerance, or minimum radius
  // As Ceres' Summary::iterations counts them (minus iteration 0): accepted, rejected and invalid
  // steps, not the one that ends at the function or parameter tolerance.
  int iterations = 0;
  int successful_steps = 0;
  double initial_cost = 0.0;  // 0.5 sum rho(|f|^2) over all residual blocks
  double final_cost = 0.0;
  std::string report;  // one line: why it stopped, iterations, costs
};

// Whether SolveSchurLm can solve `problem` with `eliminate` as the point blocks: each of them has
// 3 values and no manifold, no residual block touches two of them, and the free parameter blocks
// that are not eliminated have at most `max_reduced` tangent dimensions in all.
bool SchurLmApplies(const ceres::Problem& problem, const std::vector<double*>& eliminate,
                    int max_reduced);

// Minimises the problem's cost in place (the parameter blocks hold the result; on failure the
// initial values). Blocks of `eliminate` not in the problem, or constant, are ignored.
SchurLmSummary SolveSchurLm(ceres::Problem& problem, const std::vector<double*>& eliminate,
                            const SchurLmOptions& options);

}  // namespace jvl::optim
