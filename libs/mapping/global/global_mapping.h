// Global joint optimisation with direction priors (paper Sec. 4.3, Eq. 5-8, supplement 2).
//
// K_global = all keyframes. The energy (Eq. 7)
//
//   E = sum_n { alpha sum_j rho(e_V(n, j)) + beta sum_j e_L(n, j) + gamma e_D(n) }
//
// is assembled from plain values (no file access): the visual map (map points + keypoint
// observations), the saved IMLS correspondence set L of local mapping, a fresh point-to-IMLS
// traversal of every keyframe against the scans of its neighbouring keyframes (Eq. 2-3, as in
// local mapping step 2-4 but with the stored downsampled scans and the current poses), and one
// direction projection residual per keyframe associated with a direction prior (Eq. 6). The
// cost functions, weights rule and solver are jvl::optim's (docs/optimization.md).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "direction/vp_priors.h"
#include "geometry/calibration.h"
#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "geometry/trajectory.h"
#include "lidar/association.h"
#include "optim/joint_problem.h"

namespace jvl::mapping {

// A verified loop (loop_detect): keyframe rows of its two ends and the relative pose measured
// between them (cam0 frames).
struct LoopConstraint {
  int64_t query = 0;  // The later keyframe ...
  int64_t match = 0;  // ... and the earlier one it revisits (match < query).
  Rigid3d match_from_query;
  // Visual loops: points of the match keyframe (its cam0 frame) seen in both images. Each enters
  // the visual term as a map point observed by both keyframes.
  struct Point {
    Eigen::Vector3d p_match = Eigen::Vector3d::Zero();
    Eigen::Vector2d match_uv = Eigen::Vector2d::Zero(), query_uv = Eigen::Vector2d::Zero();
    int match_octave = 0, query_octave = 0;
  };
  std::vector<Point> points;
};

// Everything the global problem needs; keyframe references are rows of `keyframes`.
struct GlobalMapInput {
  PinholeCamera camera;
  CameraChoice camera_choice;  // The camera the visual map was built from (offset from cam0).
  Trajectory keyframes;        // Frames + current (local-mapping refined) world_from_cam0.
  std::vector<Eigen::Vector3d> map_points;             // World.
  std::vector<optim::VisualObservation> observations;  // keyframe = row.
  std::vector<optim::ImlsCorrespondence> saved_imls;   // The set L; n, c = rows.
  // (Part of) the set L already summed per keyframe pair (optim::AggregateImls; n, c = rows): the
  // compact form a caller may pass instead of millions of correspondences. Needs the compressed
  // e_L form (JointProblemOptions::compress_imls, no Huber kernel on e_L).
  std::vector<optim::ImlsPair> saved_imls_pairs;
  std::vector<lidar::StoredScan> scans;              // One per keyframe row (may be empty).
  std::vector<direction::VpAssociation> directions;  // Any frames; non-keyframes skipped.
  // Every VP of the vps artifact as a camera ray (any frames): the candidates of the vertical
  // direction prior (GlobalMappingOptions::use_vertical). Empty: no vertical prior.
  std::vector<direction::VpRay> vp_rays;
  // The odometry of the odometry term e_O (GlobalMappingOptions::use_odometry): any trajectory
  // holding the keyframes' frames (e.g. the lidar_odom prior). Empty: no e_O.
  Trajectory odometry;
  // Per row of `odometry` (optional; empty: every frame alike): how well the frame's registration
  // was conditioned, lidar_odom's smallest normalised eigenvalue of the registration's normal
  // matrix (its diagnostics/min_eigenvalue; <= 0: the frame was not registered). Where it is
  // small the scan held the motion weakly along some direction (a street without cross
  // structure) and e_O's sigma there grows (GlobalMappingOptions::odometry_conditioning).
  std::vector<double> odometry_conditioning;
  // Loops (GlobalMappingOptions::use_loops): the keyframes are corrected before the first round
  // (ApplyLoopCorrections), and every round adds point-to-IMLS correspondences of each loop's
  // query scan against the scans around its match; a visual loop's points join the visual term
  // (AddLoopPoints).
  std::vector<LoopConstraint> loops;
  void Check() const;
};

// The points of the visual loops as map points (world = the match keyframe's current pose x
// p_match) observed by both ends; after the visual term's selection, so that all of them stay.
// Returns the observations added.
int64_t AddLoopPoints(GlobalMapInput* input);

// Algorithm 1 of the supplement for every loop, in the order of their query keyframes: the
// query's pose becomes match x match_from_query, the keyframes between match and query get
// the correction spread linearly over the frames (optim::DistributeCorrection, log/exp on the
// rotation), and the keyframes after the query move with it. A map point follows the correction
// of its first observing keyframe. Returns the largest change of a keyframe position (m).
double ApplyLoopCorrections(GlobalMapInput* input);

// Fresh point-to-IMLS traversal (local mapping steps 2-4 for every keyframe).
struct ImlsTraversalOptions {
  int scan_map_size = 10;  // N: model = keyframes i < n with f_n - f_i <= N (at least n-1).
  // Fewer samples per list than the local mapping's 100: the global problem holds every
  // keyframe's correspondences at once.
  lidar::AssociationOptions association{30};
  void Check() const;
};

// Global defaults of the joint problem and the solver (where they differ from local mapping's).
optim::JointProblemOptions DefaultGlobalJointOptions();
optim::SolveOptions DefaultGlobalSolveOptions();

// The defaults are global_opt's (docs/global_opt.md, "Default configuration"): made for the
// output of local mapping, whose map points are consistent with the keyframe poses.
struct GlobalMappingOptions {
  // alpha/beta/gamma (<= 0: ResolveWeights rule), sigmas; the visual gate (chi2(2, 0.95)) and the
  // holding of weak map points (docs/global_opt.md "Long sequences with free map points").
  optim::JointProblemOptions joint = DefaultGlobalJointOptions();
  optim::SolveOptions solve = DefaultGlobalSolveOptions();  // LM iterations, tolerance, threads.
  ImlsTraversalOptions traversal;
  bool use_directions = true;   // false: the --no-direction ablation.
  bool use_saved_imls = true;   // the set L of local mapping
  bool fresh_traversal = true;  // the fresh Eq. (3) traversal of all keyframes
  // Rounds of (fresh traversal at the current poses, LM solve); round r > 0 starts from round
  // r - 1's poses and map points. 1 = the paper's single pass. 4: e_D in three rounds, each
  // re-associated at the last one's poses (docs/global_opt.md "Rounds": on the highway drives
  // of the gains table 2 -> 4 rounds took APE with direction priors 0.28-1.05 m down to
  // 0.15-0.31 m; the urban and suburban drives and KITTI 04 moved by <= 3.3 mm).
  int rounds = 4;
  // Rounds stop early (after e_O and e_D have entered) once a round changed no
  // keyframe-to-keyframe motion by more than this (m; 0 = always `rounds` rounds).
  double round_tolerance_m = 0;
  // Rounds before this one leave the direction residuals out (0 = directions in every round).
  int first_direction_round = 1;
  // Where d_w comes from when e_D enters the problem:
  //  - kPrior: the directions artifact (direction_cluster's d_w, i.e. the prior's rotations;
  //    the paper's supplement 1.4);
  //  - kRefit: re-estimated per cluster from the current keyframe rotations (after the warm-start
  //    rounds) as the robust mean of the back-projected VPs R_wn K^-1 v
  //    (direction::RefitDirections; far VPs are dropped), then fixed;
  //  - kFree: as kRefit, but each cluster's d_w is then a free unit-vector block optimised
  //    with the poses (a landmark at infinity), so that the gauge keyframe and the other terms
  //    fix its absolute orientation and e_D only makes the cluster's keyframes agree.
  enum class DirectionSource { kPrior, kRefit, kFree };
  DirectionSource direction_source = DirectionSource::kFree;
  double refit_outlier_deg = 1.0;  // smallest outlier gate (direction::RefitDirections)
  int refit_min_support = 3;       // clusters with fewer inlier keyframes are left out
  // sigma of e_D in pixels (its whitening, see JointProblemOptions::direction_sigma_px).
  // <= 0: estimated when e_D enters the problem from the median of |v - pi(R_nw d_w)| at the
  // current poses / sqrt(2 ln 2) (2D Gaussian), at least min_direction_sigma_px, times the AR(1)
  // inflation sqrt((1 + rho) / (1 - rho)) of the errors' lag-1 correlation rho within the
  // clusters (direction::DirectionErrorCorrelation). The weight rule then balances whitened
  // residuals.
  double direction_sigma_px = 0.0;
  double min_direction_sigma_px = 0.5;
  // Estimated sigma per image axis: sigma_u and sigma_v from the medians of |u error| and
  // |v error| / 0.6745 (1D Gaussians), each at least min_direction_sigma_px. On sloped roads the
  // VP's row also follows the grade ahead, so v scatters more and its part weighs less.
  bool direction_sigma_per_axis = false;
  // Vertical direction prior (beyond the paper): with e_D, one free world direction shared by
  // the vertical VPs of every keyframe (direction::SelectVertical at the poses where e_D enters),
  // as ray-form e_D residuals whitened by the sigma of the rule below and weighted by gamma like
  // e_D. It ties roll and pitch along the whole drive.
  bool use_vertical = true;
  double vertical_max_deg = 10.0;     // candidates: VPs within this of the world's up
  double vertical_outlier_deg = 1.0;  // smallest gate of the robust mean
  double min_vertical_sigma_deg = 0.05;
  // The vertical prior's weight from the evidence that the solution tilts (docs/global_opt.md
  // "Vertical direction prior"): D = the low-frequency disagreement between the vertical VPs
  // and the poses where e_D enters (direction::MeasureSlowError over +-vertical_half_window
  // frames: its slow_deg, along the direction the slow error is largest in). The VPs are themselves
  // slowly biased by up to about vertical_bias_deg (B); where D <= B they show no tilt of the
  // solution and the prior is left out, otherwise its sigma is B D / sqrt(D^2 - B^2) (at least
  // min_vertical_sigma_deg): from off at D = B down to B where D >> B. vertical_bias_deg = 0, or
  // fewer than 3 keyframes: sigma from the VPs' spread (SelectVertical's AR(1)-inflated median
  // angle).
  double vertical_bias_deg = 0.1;
  // B is at least this share of the VPs' white spread (SlowError::white_deg, larger axis):
  // noisier VPs are more slowly biased too (slow / white on the drives measured: 0.36-1.0, real
  // KITTI 04 0.41; docs/global_opt.md).
  double vertical_bias_per_white = 0.35;
  int vertical_half_window = 10;
  // > 0: the vertical prior's sigma (deg) as given (neither rule above).
  double vertical_sigma_deg = 0.0;
  // Odometry term e_O (beyond the paper, docs/global_opt.md "Odometry term"): from the round
  // after the first on, the motion of GlobalMapInput::odometry between consecutive keyframes
  // (optim::RelativePoseCost), whitened by its noise per axis as measured against the first
  // round's solution (1.4826 x the median absolute residual per frame of the interval; an
  // interval of n frames: sigma x sqrt(n); each at least the minimum below) and robust
  // (JointProblemOptions::relative_cauchy). An odometry is locally smoother than the
  // other terms where it tracks, and its registration steps fall to the kernel.
  bool use_odometry = true;
  // Pairs whose whitened 6-vector norm at the first round's solution exceeds this gate are left
  // out (the odometry's steps; sqrt(chi2(6, 0.99)) = 4.1; <= 0: keep all).
  double odometry_gate = 4.1;
  double min_odometry_sigma_m = 0.001;
  double min_odometry_sigma_deg = 0.01;
  // With GlobalMapInput::odometry_conditioning: a frame's e_O sigma (rotation and translation)
  // is times sqrt(lambda_ref / lambda), lambda its smallest normalised eigenvalue and lambda_ref
  // the median over the odometry's registered frames, clamped to [1, odometry_max_inflation]
  // (a frame without a registration: the maximum). A least-squares estimate's variance along its
  // weakest direction is 1 / lambda_min times the residuals' variance; where lidar_odom slid
  // along a street, e_O no longer holds the slide in place. A pair of keyframes n frames apart
  // sums its frames' variances (n frames alike: sigma x sqrt(n), as without). The sigma of the
  // drive (above) is measured on residuals divided by the same factor.
  bool odometry_conditioning = true;
  double odometry_max_inflation = 10.0;
  // Local noise of e_O (beyond the paper): the odometry's errors come in stretches (a street
  // where the registration slides, the biased scans of an open road), not frame by frame. Each
  // pair's sigma (after the conditioning) is also multiplied by the median whitened residual norm
  // of the pairs within odometry_local_window pairs on either side, itself included and gated
  // pairs included, at the first round's solution, divided by that median over the whole drive;
  // clamped to [1, odometry_local_max]. An isolated step leaves its neighbours' median as it is
  // (the gate takes the step out); a stretch where the odometry disagrees with the other terms
  // pair after pair weighs less there. 0: off.
  int odometry_local_window = 5;
  double odometry_local_max = 3.0;
  // Motion term e_M (beyond the paper, docs/global_opt.md "Motion term"): in every round, each
  // three consecutive keyframes' change of body-frame velocity per frame
  // (optim::MotionSmoothnessCost), whitened by the vehicle's acceleration noise per axis of the
  // camera frame (x right, y down, z forward; metres per frame at 10 Hz) and robust
  // (JointProblemOptions::motion_cauchy). Keyframes n_ab and n_bc frames apart: sigma x
  // sqrt((n_ab + n_bc) / 2). The default is 1.4826 x the median absolute deviation of that
  // change in the real KITTI ground truth of sequences 09 and 10 (../shared/data; x 4.0/4.2,
  // y 3.2/3.5, z 8.8/9.1 mm): a car's own motion, not a tuned weight.
  bool use_motion = true;
  // Surface term e_S (beyond the paper, docs/global_opt.md "Surface term"): in every round,
  // each visual observation's map point against the LiDAR surface of its keyframe's own scan.
  bool use_surface = true;
  // A map point farther than this from its keyframe's surface is not on it (m).
  double surface_max_distance_m = 0.15;
  Eigen::Vector3d motion_sigma_m = Eigen::Vector3d(0.0041, 0.0034, 0.0090);
  // > 0: the visual term uses a subset of the map points that still gives every keyframe at
  // least this many observations, or all of its own (SelectObservations): the cost of a
  // free-map-point solve grows with the observations. 0 = every point.
  int points_per_keyframe = 200;
  // Loops of GlobalMapInput::loops: corrected before the first round and tied by IMLS
  // correspondences of the query scan against the scans of the keyframes within
  // traversal.scan_map_size frames of the match (false: the --no-loops ablation).
  bool use_loops = true;
  // The visual loops' points in the visual term (AddLoopPoints); those whose two views do not
  // fix their depth are left out (held at the place they were put, they anchored the solution
  // there: docs/loop_detect.md).
  bool use_loop_points = true;
  void Check() const;

  // Preset for inputs whose map points are not consistent with the poses (e.g. placed from the
  // truth while the poses drift, as in the synthetic problems of the tests): every observation
  // and every map point in the problem and free, LM to a relative cost change of 1e-6.
  static GlobalMappingOptions EveryObservation();
};

struct GlobalMappingResult {
  optim::JointSolveResult solve;
  Trajectory keyframes;  // Optimised (same frames as the input keyframes).
  int64_t saved_imls = 0, fresh_imls = 0;
  int64_t loops_used = 0, loop_imls = 0;  // Loops entered; their correspondences (last round);
  int64_t loop_visual = 0;                // their visual observations (two per loop point).
  double loop_correction_m = 0;           // Largest keyframe move by the loop correction.
  int64_t directions_used = 0, directions_not_keyframe = 0, directions_at_infinity = 0;
  // DirectionSource::kRefit: VPs dropped as outliers / in too small clusters, and the change of
  // each cluster's d_w (degrees) against the directions artifact.
  int64_t directions_outliers = 0, directions_small_cluster = 0;
  std::map<int32_t, double> direction_change_deg;
  double direction_sigma_px = 0;                 // sigma of e_D used (given or estimated)
  double direction_sigma_v_px = 0;               // its v part when estimated per axis (0: as above)
  std::vector<Eigen::Vector3d> free_directions;  // kFree: optimised d_w per kept cluster
  std::vector<int32_t> free_direction_clusters;  // cluster id of each free_directions entry
  bool direction_sigma_estimated = false;
  // Estimated sigma: the lag-1 correlation of e_D within the clusters it was inflated for.
  double direction_rho = 0;
  // The vertical direction prior: keyframes with a candidate, inliers used, outliers, the sigma
  // used (deg; 0 when left out), which rule gave it ("given", "evidence", "spread", "left_out";
  // empty when the prior never entered), the lag-1 correlation of its errors and the optimised
  // direction (NaN when not used).
  int64_t vertical_candidates = 0, vertical_used = 0, vertical_outliers = 0;
  double vertical_sigma_deg = 0, vertical_rho = 0;
  std::string vertical_sigma_rule;
  // Its low-frequency disagreement with the poses where e_D enters (deg, SlowError::slow_deg)
  // and the white part of its spread (deg, larger axis).
  double vertical_disagreement_deg = 0, vertical_white_deg = 0;
  double vertical_bias_deg = 0;  // the slow bias B used (0: spread rule)
  // The odometry term: keyframe pairs, the measured per-frame sigmas, and the pairs whose
  // whitened residual ended above the kernel scale (down-weighted: the odometry's steps).
  int64_t odometry_pairs = 0, odometry_gated = 0, odometry_outliers = 0;
  // Pairs whose sigma the conditioning raised by more than 2x (odometry_conditioning).
  int64_t odometry_inflated = 0;
  // Pairs kept in e_O whose sigma the local noise raised (odometry_local_window), and the
  // drive's median whitened residual norm the local medians are divided by.
  int64_t odometry_local_inflated = 0;
  double odometry_median_norm = 0;
  int64_t surface_constraints = 0;    // e_S of the last round
  bool odometry_conditioned = false;  // The conditioning of the odometry's frames was used.
  Eigen::Vector3d odometry_sigma_m = Eigen::Vector3d::Zero();  // per frame, camera x, y, z
  Eigen::Vector3d odometry_sigma_deg = Eigen::Vector3d::Zero();
  // The motion term: keyframe triples, and those whose whitened residual ended above the kernel
  // scale (a real acceleration, or a place where the other terms move a keyframe).
  int64_t motion_triples = 0, motion_outliers = 0;
  Eigen::Vector3d vertical_direction = Eigen::Vector3d::Constant(std::nan(""));
  double traversal_time_s = 0;
  double total_time_s = 0;
  int rounds = 0;
  std::vector<double> round_motion_change_m;  // per round, the largest motion change it made
  int total_iterations = 0;  // LM iterations over all rounds (solve.iterations: last round)
  // GlobalMappingOptions::points_per_keyframe: what the visual term kept of the input.
  int64_t input_observations = 0, selected_observations = 0;
  int64_t input_points = 0, selected_points = 0;
};

// The e_D residuals of `priors` (fixed d_w; the selection and re-estimation of the priors are
// jvl::direction's, direction/vp_priors.h).
std::vector<optim::DirectionConstraint> ToDirectionConstraints(
    const std::vector<direction::VpPrior>& priors);

const char* ToString(GlobalMappingOptions::DirectionSource source);

// Keeps the observations of a subset of the map points (`num_points` of them) such that every
// keyframe keeps min(per_keyframe, its own count) observations: points are visited by decreasing
// number of observations (longer tracks: more parallax; ties by index) and taken while one of
// their keyframes has fewer than `per_keyframe` taken; all observations of a taken point are
// kept, in input order. per_keyframe <= 0 keeps everything. Returns the number of map points
// with an observation left. Deterministic.
int64_t SelectObservations(std::vector<optim::VisualObservation>* observations, size_t num_points,
                           int per_keyframe);

// Eq. (2)-(3) for every keyframe n (in parallel, deterministic): the model is the scans of
// keyframes within N frames before n, placed with the current poses; up to 9 x samples_per_list
// points of n's scan (IMLS-SLAM sampling on the stored normals) are projected onto it. Each
// projection gives (n, c = keyframe of the nearest model point, p_x, c_p_y, n_c).
std::vector<optim::ImlsCorrespondence> TraverseImls(const Trajectory& keyframes,
                                                    const std::vector<lidar::StoredScan>& scans,
                                                    const ImlsTraversalOptions& options,
                                                    int threads);

// Builds and solves Eq. (7) (gauge: the first keyframe fixed). A failed solve is reported in
// result.solve.usable; the keyframes then keep their input poses. The input is taken by value:
// its scans are released once the last fresh traversal is done, before the last solve (on a
// long sequence they are a large part of the memory); a caller that needs them afterwards keeps
// its own copy or passes a copy.
GlobalMappingResult OptimizeGlobal(GlobalMapInput input, const GlobalMappingOptions& options);

// Residual counts, costs before/after by type, weights, solver summary (the "stats" attribute).
nlohmann::json GlobalStatsJson(const GlobalMappingResult& result,
                               const GlobalMappingOptions& options);

// Accumulated map: every keyframe's scan placed with `keyframes` poses, voxel-downsampled
// (first point per voxel, keyframe order). voxel_size <= 0 keeps every point.
std::vector<Eigen::Vector3f> AccumulateMap(const Trajectory& keyframes,
                                           const std::vector<lidar::StoredScan>& scans,
                                           double voxel_size);

}  // namespace jvl::mapping
