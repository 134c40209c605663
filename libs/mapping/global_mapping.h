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
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "geometry/trajectory.h"
#include "optim/joint_problem.h"

namespace jvl::mapping {

// The preprocessed, voxel-downsampled scan of one keyframe in its own cam0 frame.
struct KeyframeScan {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;  // Unit; a zero normal marks a point without one.
};

// A VP of a frame associated with a direction prior d_w (directions artifact).
struct DirectionAssociation {
  int64_t frame = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // Pixels; NaN if the VP is at infinity.
  Eigen::Vector3d direction_world = Eigen::Vector3d::UnitZ();
  int32_t cluster = 0;
};

// Everything the global problem needs; keyframe references are rows of `keyframes`.
struct GlobalMapInput {
  PinholeCamera camera;
  Trajectory keyframes;  // Frames + current (local-mapping refined) world_from_cam0.
  std::vector<Eigen::Vector3d> map_points;             // World.
  std::vector<optim::VisualObservation> observations;  // keyframe = row.
  std::vector<optim::ImlsCorrespondence> saved_imls;   // The set L; n, c = rows.
  std::vector<KeyframeScan> scans;                     // One per keyframe row (may be empty).
  std::vector<DirectionAssociation> directions;        // Any frames; non-keyframes skipped.
  void Check() const;
};

// Fresh point-to-IMLS traversal (local mapping steps 2-4 for every keyframe).
struct ImlsTraversalOptions {
  int scan_map_frames = 10;    // N: model = keyframes i < n with f_n - f_i <= N (at least n-1).
  int samples_per_list = 30;   // IMLS-SLAM sampling: points taken from each of the 9 lists.
  double kernel_h = 0.3;       // m, h of W_i in Eq. (2).
  double search_radius = 0.6;  // m, model neighbours of Eq. (2).
  double max_distance = 0.5;   // m, |I(x)| above this: no correspondence.
  void Check() const;
};

struct GlobalMappingOptions {
  optim::JointProblemOptions joint;  // alpha/beta/gamma (<= 0: ResolveWeights rule), sigmas.
  optim::SolveOptions solve;         // LM iterations, threads.
  ImlsTraversalOptions traversal;
  bool use_directions = true;   // false: the --no-direction ablation.
  bool use_saved_imls = true;   // the set L of local mapping
  bool fresh_traversal = true;  // the fresh Eq. (3) traversal of all keyframes
  // Rounds of (fresh traversal at the current poses, LM solve); round r > 0 starts from round
  // r - 1's poses and map points. 1 = the paper's single pass.
  int rounds = 2;
  // Rounds before this one leave the direction residuals out (0 = directions in every round).
  int first_direction_round = 1;
  void Check() const;
};

struct DirectionSelection {
  std::vector<optim::DirectionConstraint> constraints;  // keyframe = row.
  int64_t not_keyframe = 0;  // Associations of frames that are not keyframes.
  int64_t at_infinity = 0;   // Non-finite VP (skipped: e_D needs a finite v).
};

struct GlobalMappingResult {
  optim::JointSolveResult solve;
  Trajectory keyframes;  // Optimised (same frames as the input keyframes).
  int64_t saved_imls = 0, fresh_imls = 0;
  int64_t directions_used = 0, directions_not_keyframe = 0, directions_at_infinity = 0;
  double traversal_time_s = 0;
  double total_time_s = 0;
  int rounds = 0;
  int total_iterations = 0;  // LM iterations over all rounds (solve.iterations: last round)
};

// Direction residual inputs: one per keyframe with an association and a finite VP.
DirectionSelection SelectDirections(const Trajectory& keyframes,
                                    const std::vector<DirectionAssociation>& associations);

// Eq. (2)-(3) for every keyframe n (in parallel, deterministic): the model is the scans of
// keyframes within N frames before n, placed with the current poses; up to 9 x samples_per_list
// points of n's scan (IMLS-SLAM sampling on the stored normals) are projected onto it. Each
// projection gives (n, c = keyframe of the nearest model point, p_x, c_p_y, n_c).
std::vector<optim::ImlsCorrespondence> TraverseImls(const Trajectory& keyframes,
                                                    const std::vector<KeyframeScan>& scans,
                                                    const ImlsTraversalOptions& options,
                                                    int threads);

// Builds and solves Eq. (7) (gauge: the first keyframe fixed). A failed solve is reported in
// result.solve.usable; the keyframes then keep their input poses.
GlobalMappingResult OptimizeGlobal(const GlobalMapInput& input,
                                   const GlobalMappingOptions& options);

// Residual counts, costs before/after by type, weights, solver summary (the "stats" attribute).
nlohmann::json GlobalStatsJson(const GlobalMappingResult& result,
                               const GlobalMappingOptions& options);

// Accumulated map: every keyframe's scan placed with `keyframes` poses, voxel-downsampled
// (first point per voxel, keyframe order). voxel_size <= 0 keeps every point.
std::vector<Eigen::Vector3f> AccumulateMap(const Trajectory& keyframes,
                                           const std::vector<KeyframeScan>& scans,
                                           double voxel_size);

}  // namespace jvl::mapping
