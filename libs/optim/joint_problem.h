// Joint visual + point-to-IMLS + direction problem (Eq. 4 local energy, Eq. 7 global energy).
//
//   E = alpha sum rho_V(|e_V|^2) + beta sum rho_L(e_L^2) + gamma sum rho_D(|e_D|^2)
//
// BuildJointProblem() turns plain inputs into a ceres::Problem (poses as world_from_cam blocks on
// the pose manifold, map points as 3-blocks, gauge fixed explicitly); SolveJointProblem() runs
// Levenberg-Marquardt and reports cost per residual type before/after. local_map (Sec. 4.2) and
// global_opt (Sec. 4.3) both fill JointProblemInput; see docs/optimization.md.
#pragma once

#include <ceres/problem.h>

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "optim/imls_pair_cost.h"
#include "optim/pose_block.h"

namespace jvl::optim {

// One keypoint observation x^j of map point X^j in keyframe i (Sec. 4.2 step 1).
struct VisualObservation {
  int64_t keyframe = 0;   // key into JointProblemInput::poses
  int32_t map_point = 0;  // row in JointProblemInput::map_points
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  int octave = 0;  // ORB pyramid level: sigma = scale_factor^octave px
};

// One saved IMLS correspondence (n, c, p_x, c_p_y, n_c) of the set L (Eq. 3, supplement Eq. 1).
struct ImlsCorrespondence {
  int64_t n = 0;  // keyframe owning the sampled point p_x (p_x in n's frame)
  int64_t c = 0;  // keyframe owning the nearest model point (c_p_y, c_normal in c's frame)
  Eigen::Vector3d p_x = Eigen::Vector3d::Zero();
  Eigen::Vector3d c_p_y = Eigen::Vector3d::Zero();
  Eigen::Vector3d c_normal = Eigen::Vector3d::UnitZ();  // unit
};

// All correspondences of one ordered keyframe pair (n, c), summed (imls_pair_cost.h): the form in
// which a large, fixed set such as the saved set L is kept across solves.
struct ImlsPair {
  int64_t n = 0;
  int64_t c = 0;
  ImlsPairAccumulator sum;
};

// Groups correspondences by (n, c): pairs in (n, c) order, each pair's sum in input order.
std::vector<ImlsPair> AggregateImls(const std::vector<ImlsCorrespondence>& correspondences);

// A vanishing point v of keyframe `keyframe` associated with a world direction prior d_w (Eq. 6).
struct DirectionConstraint {
  int64_t keyframe = 0;
  Eigen::Vector2d vp = Eigen::Vector2d::Zero();                // pixels, finite
  Eigen::Vector3d direction_world = Eigen::Vector3d::UnitZ();  // used if free_direction < 0
  // >= 0: d_w is JointProblemInput::free_directions[free_direction], a unit-sphere parameter
  // block optimised with the poses (shared by the constraints of one direction cluster).
  int32_t free_direction = -1;
  // Ray form (needs free_direction >= 0): the observation is the unit ray `ray` in the camera
  // instead of the pixel `vp` (a VP that may lie at infinity in the image, such as the vertical
  // one), residual DirectionAngleFreeCost whitened by JointProblemOptions::direction_sigma_rad.
  bool ray_form = false;
  Eigen::Vector3d ray = Eigen::Vector3d::UnitZ();
};

// A measured relative motion between two keyframes, Z = world_from_i^-1 world_from_j (e_O; beyond
// the paper: an odometry's motion, docs/global_opt.md "Odometry term"), with its noise.
struct RelativePoseConstraint {
  int64_t i = 0;
  int64_t j = 0;
  Rigid3d i_from_j;
  // Noise per axis of the residual (frame j): rotation (radians) and translation (metres).
  Eigen::Vector3d sigma_rad = Eigen::Vector3d::Constant(1e-3);
  Eigen::Vector3d sigma_m = Eigen::Vector3d::Constant(1e-2);
};

// A vehicle-motion constraint on three consecutive keyframes a, b, c (e_M; beyond the paper,
// docs/global_opt.md "Motion term"): their body-frame velocity per frame should not change by
// more than the vehicle's acceleration allows, sigma per camera axis of the rotations midway
// between a and b, b and c (metres per frame; optim::MotionSmoothnessCost).
struct MotionConstraint {
  int64_t a = 0, b = 0, c = 0;
  double frames_ab = 1.0, frames_bc = 1.0;
  Eigen::Vector3d sigma_m = Eigen::Vector3d::Constant(1e-2);
};

// A map point on the LiDAR surface of one of its observing keyframes (e_S; beyond the paper,
// docs/global_opt.md "Surface term"): the projection of the point onto the IMLS surface of the
// keyframe's own scan and its unit normal, in the keyframe's frame.
struct PointSurfaceConstraint {
  int64_t keyframe = 0;
  int32_t map_point = 0;
  Eigen::Vector3d k_p_y = Eigen::Vector3d::Zero();
  Eigen::Vector3d k_normal = Eigen::Vector3d::UnitZ();
};

struct JointProblemInput {
  PinholeCamera camera;
  // The observing camera's offset from the poses' frame (camera 0): x_camera = x_cam0 + offset.
  // Zero for camera 0; another rectified camera's Calibration::CameraOffset (same orientation).
  Eigen::Vector3d camera_offset = Eigen::Vector3d::Zero();
  std::map<int64_t, Rigid3d> poses;         // keyframe id -> world_from_cam (initial values)
  std::set<int64_t> fixed;                  // keyframes held constant; empty: the first id is fixed
  std::vector<Eigen::Vector3d> map_points;  // world frame
  std::vector<VisualObservation> observations;
  // If set, used instead of `observations` (a caller that keeps millions of observations across
  // several solves passes them without a copy; they must outlive the build).
  const std::vector<VisualObservation>* shared_observations = nullptr;
  // Map points from this row on are left out, not held, when weak (max_point_sigma_ratio): a
  // point placed through an uncertain pose must not anchor the solution where it was put.
  size_t drop_weak_from = static_cast<size_t>(-1);
  const std::vector<VisualObservation>& Observations() const {
    return shared_observations != nullptr ? *shared_observations : observations;
  }
  std::vector<ImlsCorrespondence> imls;
  // Correspondences already summed per keyframe pair (AggregateImls); merged with `imls` of the
  // same pair. Needs the compressed form (compress_imls, no Huber kernel on e_L).
  std::vector<ImlsPair> imls_pairs;
  std::vector<DirectionConstraint> directions;
  std::vector<Eigen::Vector3d> free_directions;        // initial values of the free d_w blocks
  std::vector<RelativePoseConstraint> relative_poses;  // e_O (weight 1 on whitened residuals)
  std::vector<MotionConstraint> motion;                // e_M (weight 1 on whitened residuals)
  // e_S (weight 1 on whitened residuals); only points that are in the visual term are used.
  std::vector<PointSurfaceConstraint> point_surfaces;
};

struct JointProblemOptions {
  // Weights of Eq. (4)/(7). A weight <= 0 means "from the residual counts" (the paper: alpha = 1,
  // the others set according to the number of residuals). With N_ref = N_V if there are visual
  // residuals, else max(N_L, N_D):
  //   beta = alpha * beta_scale * N_ref / N_L,   gamma = alpha * gamma_scale * N_ref / N_D,
  // i.e. every residual type gets the same total weight as the visual term (times its scale).
  // A type without residuals gets alpha * scale (irrelevant).
  double alpha = 1.0;
  double beta = 0.0;
  double gamma = 0.0;
  double beta_scale = 1.0;
  double gamma_scale = 1.0;
  // Noise models (square-root information = 1 / sigma).
  double octave_scale_factor = 1.2;  // ORB-SLAM: sigma_V = 1.2^octave px
  double imls_sigma_m = 0.05;        // e_L in metres
  // > 1: e_L's noise per keyframe pair from the pair's own fit (summed form only, i.e.
  // SumsImlsPerPair): a pair whose RMS point-to-surface residual at the initial poses is f times
  // the median pair's (f > 1) gets the sigma imls_sigma_m x min(f, imls_pair_noise_max). One
  // sigma for all pairs overstates what a rough surface (vegetation, clutter) tells: its
  // residuals are larger at any pose. The pairs of a fixed (gauge) keyframe always keep
  // imls_sigma_m. <= 1: one sigma for every pair.
  double imls_pair_noise_max = 0.0;
  double direction_sigma_px = 1.0;  // e_D in pixels (image u; v too unless set below)
  // e_D's v (image row) component, when it has a noise of its own (> 0): on sloped roads the
  // VP's row also holds the grade of the road ahead, which varies along one direction prior.
  double direction_sigma_v_px = 0.0;
  double direction_sigma_rad = 0.005;  // e_D of ray-form constraints (radians)
  // Huber thresholds on the whitened residual norm; <= 0 disables. ORB-SLAM mono: sqrt(5.991).
  double visual_huber = 2.447651936039926;
  double imls_huber = 0.0;
  double direction_huber = 0.0;
  double direction_min_z = 0.05;  // clamp of DirectionProjectionCost (see cost_functions.h)
  // Cauchy kernel of e_O on the whitened 6-vector's norm (<= 0: none): a measured motion that
  // disagrees with the other terms by many sigmas (an odometry's registration step) loses its
  // pull instead of dragging the solution.
  double relative_cauchy = 3.0;
  // Cauchy kernel of e_M on its whitened norm (<= 0: none): a real acceleration (braking, a
  // turn's start) many sigmas out keeps a bounded cost.
  double motion_cauchy = 3.0;
  // e_S: sigma of a map point's distance to the LiDAR surface (m) and Cauchy kernel on the
  // whitened residual (<= 0: none). Corner keypoints lie on depth edges, where the surface
  // found may be the wrong one: the kernel bounds them.
  double surface_sigma_m = 0.05;
  double surface_cauchy = 1.0;
  // Outlier gate on e_V at the initial estimate (whitened squared reprojection error; <= 0: off).
  // Observations above it are left out of the problem, and with free map points so is every
  // point left with fewer than 2 observations (its depth would be unconstrained). ORB-SLAM's
  // bundle adjustments drop observations above chi2(2, 0.95) = 5.991 the same way.
  double visual_gate_chi2 = 0.0;
  // Free map points whose position is poorly determined by their observations at the initial
  // estimate are held constant (<= 0: off): those whose largest standard deviation
  // 1 / sqrt(lambda_min(sum J^T J)) (J = d e_V / dX, whitened) exceeds this fraction of their
  // distance to the nearest observing camera. Such points (far, small parallax, coarse pyramid
  // levels) let an LM step fling them behind a camera, which fails the evaluation and wastes
  // the iteration; held constant they still constrain the poses' rotations, as far points do.
  double max_point_sigma_ratio = 0.0;
  // What happens to those points: held constant (false) or left out with their observations
  // (true; counted in gated_observations). Held, they keep the local map's geometry, drift
  // included, and pin the rotations to it.
  bool drop_weak_points = false;
  bool optimize_map_points = true;
  bool analytic_jacobians = true;  // analytic e_L / e_D twins (faster, see docs/optimization.md)
  // Without a Huber kernel on e_L, all correspondences of one keyframe pair (n, c) form one exact
  // residual block (imls_pair_cost.h): same cost and LM steps, far fewer blocks. false: one block
  // per correspondence (the form of the equations; used by tests to check the equivalence).
  bool compress_imls = true;
  // Whether e_L is built as one block per keyframe pair: compress_imls and no Huber kernel on e_L.
  bool SumsImlsPerPair() const { return compress_imls && imls_huber <= 0; }
  void Check() const;
};

struct JointWeights {
  double alpha = 1.0, beta = 1.0, gamma = 1.0;
};

// Number of e_L residuals of an input: imls plus the correspondences summed in imls_pairs.
int64_t CountImls(const JointProblemInput& input);

// Weights for the given residual counts following the rule documented on JointProblemOptions.
JointWeights ResolveWeights(const JointProblemOptions& options, int64_t num_visual,
                            int64_t num_imls, int64_t num_directions);

// The built problem: owns parameter storage (stable addresses) and the ceres::Problem.
struct JointProblem {
  std::map<int64_t, PoseBlock> poses;
  std::vector<std::array<double, 3>> map_points;
  std::vector<std::array<double, 3>> free_directions;
  std::unique_ptr<ceres::Problem> problem;
  std::vector<ceres::ResidualBlockId> visual_blocks, imls_blocks, direction_blocks, relative_blocks,
      motion_blocks, surface_blocks;
  std::vector<int64_t> imls_block_counts;  // correspondences in each of imls_blocks
  std::set<int64_t> fixed;                 // effective constant poses (gauge)
  JointWeights weights;
  int64_t dropped_observations = 0;  // behind the camera at the initial estimate
  // Left out by visual_gate_chi2: observations above the gate, and the other observations of
  // free map points left with fewer than 2 (counted in gated_observations too).
  int64_t gated_observations = 0, gated_points = 0;
  int64_t weak_points = 0;  // held constant or dropped by max_point_sigma_ratio
  // imls_pair_noise_max: the median pair RMS residual at the initial poses (m) and the pairs
  // given a larger sigma.
  double imls_pair_median_rms_m = 0.0;
  int64_t imls_pairs_inflated = 0;
  bool has_free_map_points = false;
};

JointProblem BuildJointProblem(const JointProblemInput& input, const JointProblemOptions& options);

struct SolveOptions {
  int max_iterations = 100;
  // Threads of the work around the solve (IMLS traversal, scan preparation); Ceres itself runs
  // on one thread so that the result does not depend on this (joint_stats.cc).
  int threads = 1;
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
  double max_time_s = 1e9;    // a wall-clock limit makes results machine-dependent: tests only
  bool log_progress = false;  // Ceres' per-iteration log on stderr
  // Non-empty: one info log line per LM iteration ("<label> iteration k: cost, time"), the
  // progress of long solves.
  std::string progress_label;
  // The cost by term before and after the solve (JointSolveResult::before / after; two passes
  // over all residuals each). A caller that reports only some of them (global rounds, local
  // mapping) skips the rest: a skipped breakdown still holds the residual counts and, in
  // `total`, Ceres' cost before / after the solve. `after` is always evaluated when the solve
  // fails.
  bool evaluate_before = true;
  bool evaluate_after = true;
  // Linear solver of a problem with free map points: the Schur complement over the free poses
  // (and free directions) is kept dense (DENSE_SCHUR) up to this many such blocks, sparse
  // (SPARSE_SCHUR) beyond. A local window of 20 keyframes gives a 120 x 120 system, where the
  // dense matrix avoids the sparse one's per-cell lookups (13 % less local mapping time on the
  // demo drive, same result within 3e-5 m); global problems have thousands of poses.
  int dense_schur_max_blocks = 64;
  // The dense case is solved by this project's Levenberg-Marquardt (schur_lm.h: the same step
  // control and stopping rules as Ceres', without Ceres' per-solve preparation and per-cell
  // locks) instead of Ceres' DENSE_SCHUR. false: Ceres, for comparison.
  bool schur_lm = true;
  void Check() const;
};

// Cost per residual type: `cost` is what Ceres minimises (0.5 * weight * rho(|r|^2) summed),
// `rms` the root mean square of the whitened, unweighted, non-robust residual norms.
struct ResidualStats {
  int64_t count = 0;
  double cost = 0.0;
  double rms = 0.0;
};

struct JointCostBreakdown {
  ResidualStats visual, imls, direction, relative, motion, surface;
  double total = 0.0;
};

struct JointSolveResult {
  JointCostBreakdown before, after;
  JointWeights weights;
  int iterations = 0;
  int64_t imls_blocks = 0;  // residual blocks holding the e_L terms (one per pair when summed)
  double imls_pair_median_rms_m = 0.0;  // JointProblem's, see there
  int64_t imls_pairs_inflated = 0;
  // Visual observations left out when the problem was built (JointProblem's counts).
  int64_t dropped_observations = 0, gated_observations = 0, gated_points = 0, weak_points = 0;
  double time_s = 0.0;
  bool usable = false;      // Ceres returned CONVERGENCE or NO_CONVERGENCE (not FAILURE)
  std::string termination;  // Ceres' summary line
  std::string linear_solver;
  // Block sizes (rows, map point, pose) of the Schur elimination Ceres used for a Schur-type
  // solve, "2,3,6" when it ran its specialised code, "d,d,d" for the generic one; empty otherwise.
  std::string schur_structure;
  std::map<int64_t, Rigid3d> poses;              // optimised world_from_cam
  std::vector<Eigen::Vector3d> map_points;       // optimised (unchanged if not optimised)
  std::vector<Eigen::Vector3d> free_directions;  // optimised free d_w blocks (unit)
};

JointCostBreakdown EvaluateJointCost(JointProblem& problem);
JointSolveResult SolveJointProblem(JointProblem& problem, const SolveOptions& options);
// Build + solve.
JointSolveResult OptimizeJoint(const JointProblemInput& input, const JointProblemOptions& options,
                               const SolveOptions& solve_options);

}  // namespace jvl::optim
