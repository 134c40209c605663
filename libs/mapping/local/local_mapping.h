// Local mapping (paper Sec. 4.2 steps 1-5, supplement 1.2): every keyframe K_n, in arrival
// order, triggers a joint optimisation of the visual reprojection errors of its covisible
// keyframes K_local and of point-to-IMLS-surface errors between K_n's sampled scan and the scan
// model of the keyframes K_start..K_{n-1}, plus the saved correspondences of L whose two
// keyframes are both in K_local (supplement Eq. 1).
//
//   LocalMappingInput in = MakeLocalMappingInput(visual, prior, "prior");  // local_artifact.h
//   LocalMappingResult r = RunLocalMapping(in, [&](size_t row) { return PrepareKeyframeScan(..); },
//                                          options, threads, on_keyframe);
//
// Keyframes are identified by their row in the visual map (0..K-1, increasing frame index).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "geometry/trajectory.h"
#include "mapping/local/local_scan.h"
#include "optim/joint_problem.h"

namespace jvl::mapping {

struct LocalMappingInput {
  PinholeCamera camera;
  CameraChoice camera_choice;      // The camera the visual map was built from (offset from cam0).
  std::vector<int64_t> frames;     // Keyframe frame ids, increasing.
  std::vector<Rigid3d> map_poses;  // Poses the map points were triangulated with.
  std::vector<Rigid3d> prior;      // Initial world_from_cam0 of each keyframe.
  std::vector<Eigen::Vector3d> map_points;             // World, in the map_poses frame.
  std::vector<optim::VisualObservation> observations;  // keyframe = row.
  std::vector<std::array<int, 2>> covisibility;        // Keyframe rows.
  size_t size() const { return frames.size(); }
  void Check() const;
};

struct LocalMappingOptions {
  int scan_map_size = 10;  // N: K_start is the first keyframe with f_n - f_i <= N (step 2).
  // If no earlier keyframe is within N frames, S_model still gets the last this-many keyframes
  // (0 = the literal rule: no LiDAR term for such a keyframe).
  int min_model_keyframes = 1;
  // Scan association + solve rounds per keyframe. 1 = the paper (associate once, then solve);
  // more re-associates K_n's samples at the refined poses and solves again.
  int association_rounds = 1;
  // Map points with fewer observations among K_local are left out (one observation of a free
  // point constrains no pose).
  int min_point_observations = 2;
  // The next keyframe's initial pose keeps the prior motion from the refined previous one.
  bool propagate_corrections = true;
  lidar::AssociationOptions association;
  optim::JointProblemOptions joint;  // alpha, beta (<= 0: the weights rule), noise, Huber.
  optim::SolveOptions solve;         // threads is overridden by RunLocalMapping's argument.
  void Check() const;
};

// Per-keyframe figures (the artifact's stats group and the progress log).
struct KeyframeStats {
  int64_t frame = 0;
  int local_keyframes = 0;   // |K_local|.
  int model_keyframes = 0;   // Keyframes in S_model.
  int fixed_keyframes = 0;   // Poses held constant in the problem.
  int visual_residuals = 0;  // As added (after dropping points behind a camera).
  int imls_residuals = 0;    // New + reused.
  int new_correspondences = 0, reused_correspondences = 0;
  int map_points = 0;
  double cost_before = 0, cost_after = 0;  // Ceres cost (0.5 weighted sum), first/last round.
  double beta = 0;                         // Weight used.
  int iterations = 0;
  bool optimized = false;   // A solve ran and was usable.
  double correction_m = 0;  // |t| of K_n's pose change by this keyframe's optimisation.
  double time_ms = 0;       // Whole keyframe including its scan preparation.
  // scan_ms: preparing the scan, or with a prefetch (threads >= 2) waiting for it; solve_ms:
  // association, problem and solve, of which associate_ms the scan association.
  double scan_ms = 0, solve_ms = 0, associate_ms = 0;
};

struct LocalMappingResult {
  std::vector<Rigid3d> poses;                              // Refined world_from_cam0 per keyframe.
  std::vector<Eigen::Vector3d> map_points;                 // Refined (rows of the input).
  std::vector<optim::ImlsCorrespondence> correspondences;  // L; n, c are keyframe rows.
  std::vector<lidar::StoredScan> scans;                    // Per keyframe (cam0 frame).
  std::vector<KeyframeStats> stats;
};

// Step 2: row of K_start for keyframe row n (see LocalMappingOptions). Returns n when S_model is
// empty.
size_t StartKeyframe(const std::vector<int64_t>& frames, size_t n, int scan_map_size,
                     int min_model_keyframes);

// Step "K_local": n and the keyframes covisible with it that arrived before it, by time.
std::vector<int64_t> LocalKeyframes(size_t n, const std::vector<std::vector<int>>& adjacency);
std::vector<std::vector<int>> CovisibilityAdjacency(size_t num_keyframes,
                                                    const std::vector<std::array<int, 2>>& edges);

// Supplement 1.2: indices of the saved correspondences whose keyframes n and c are both local.
// `ranges[r]` is [begin, end) of keyframe r's own correspondences (n = r) in `saved`, so only
// the local keyframes' ranges are visited (L grows with the drive); indices come by keyframe.
std::vector<size_t> ReusableCorrespondences(const std::vector<optim::ImlsCorrespondence>& saved,
                                            const std::vector<std::pair<size_t, size_t>>& ranges,
                                            const std::set<int64_t>& local);

// Gauge (step 5): keyframe 0 and every pose outside K_local are fixed; if that leaves no fixed
// pose, the oldest keyframe of K_local is fixed.
std::set<int64_t> FixedKeyframes(const std::vector<int64_t>& local,
                                 const std::set<int64_t>& problem_poses);

using ScanLoader = std::function<KeyframeScan(size_t row)>;
using KeyframeCallback = std::function<void(size_t row, const KeyframeStats&)>;

LocalMappingResult RunLocalMapping(const LocalMappingInput& input, const ScanLoader& load_scan,
                                   const LocalMappingOptions& options, int threads,
                                   const KeyframeCallback& on_keyframe = {});

// Refined keyframe trajectory (frames of the input).
Trajectory RefinedKeyframes(const LocalMappingInput& input, const LocalMappingResult& result);

// Run summary (medians of the per-keyframe figures, counts); see schemas/local.schema.json.
nlohmann::json SummarizeLocalMap(const LocalMappingResult& result,
                                 const LocalMappingOptions& options);

}  // namespace jvl::mapping
