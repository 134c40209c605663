// Direction priors from vanishing points and prior orientations: Sec. 4.3 "Association of
// Direction Priors and VPs" and Algorithm 2 (bi-level mean-shift) of the supplement 1.4.
//
//   1. d = R_wc K^-1 v / |R_wc K^-1 v| for every VP, with R_wc from the prior pose of its frame.
//   2. Forward filter (Alg. 2 lines 2-8): drop d whose ground projection is more than Th_f away
//      from the prior's ground-plane motion direction fd_i.
//   3. First level (lines 9-10): mean-shift on the unit directions (bandwidth1).
//   4. Per cluster std delta and slope s of the centre's ground projection (lines 11-16); sort
//      by slope into subsets (17); keep clusters with delta <= Th_delta and size >= Th_n (18-25).
//   5. Keep Th_m clusters every Th_l metres of travelled path (26).
//   6. Second level (27-33): mean-shift on the 2D ground positions of each kept cluster's frames
//      (bandwidth2) splits it into spatially separate sub-clusters.
//   7. At most one VP per frame (Sec. 4.3); V_interval downsampling of each cluster's frames
//      (Sec. 5 "Different Number of Direction Priors").
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "geometry/camera.h"
#include "geometry/trajectory.h"

namespace jvl::direction {

// One detected vanishing point (a row of the vps artifact).
struct VpObservation {
  int64_t frame = 0;
  int vp_index = 0;  // 0..2 within its frame.
  Eigen::Vector2d uv = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Unit K^-1 v in the camera frame; if not finite it is computed from uv and the camera.
  Eigen::Vector3d direction_cam =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bool is_forward = false;  // vp_detect's own guess; used only with use_forward_flag.
  double score = 0;
};

struct DirectionClusterOptions {
  // Ground plane: world up vector. Zero = "minus the y axis of the first prior camera", which
  // for KITTI (cam0 y points down, first pose = identity) is world -y: the ground is x-z.
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  // Th_f: max angle between a VP's ground projection and the prior's motion direction.
  double forward_max_angle_deg = 10.0;
  // fd_i = t(j) - t(k) with j, k the nearest frames at least this far (m) ahead and behind;
  // closer than this in total (standing still) the camera's optical axis is used instead.
  double forward_baseline_m = 2.0;
  // Directions whose ground projection is shorter than this (steeper than ~acos) are dropped.
  double min_ground_component = 0.5;
  bool use_forward_flag = false;  // Also drop VPs that vp_detect did not flag as forward.
  // First level: bandwidth1 (deg) of the mean-shift on unit directions.
  double bandwidth1_deg = 1.5;
  // Members farther than this from their first-level mode are dropped (outliers in the basin).
  double max_member_angle_deg = 4.0;
  // Clusters whose centre slopes (ground heading mod 180 deg) are within this form one subset.
  double slope_subset_deg = 5.0;
  double max_std_deg = 1.5;  // Th_delta: max RMS angle of the members to the centre.
  // A final cluster whose members' ground headings turn steadily along the path (least-squares
  // line over the travelled distance) by more than max_sweep_deg over its length, at more than
  // max_turn_rate_deg_per_100m, is a bend, not a direction.
  double max_sweep_deg = 2.5;
  double max_turn_rate_deg_per_100m = 3.0;
  int min_size = 10;            // Th_n: min members of a kept cluster (also after each later step).
  int clusters_per_window = 1;  // Th_m: clusters kept per window of travelled distance.
  double window_length_m = 20.0;  // Th_l: window length (m of travelled path).
  double bandwidth2_m = 15.0;     // Second level: bandwidth2 (m) on 2D ground positions.
  // Second-level sub-clusters whose frames follow each other along the path closer than this
  // (m) are joined (a straight road is one run); 0 keeps the raw mean-shift split.
  double link_gap_m = 15.0;
  // V_interval: keep associations of a cluster at least this many frames apart (0 = all).
  int v_interval = 0;
  void Check() const;
};

struct DirectionClusterInfo {
  int id = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // Unit, world: the direction prior d_w.
  double std_deg = 0;  // RMS angle of all members (before V_interval) to `direction`.
  int members = 0;     // Members before V_interval.
  int size = 0;        // Associations written (after V_interval).
  int64_t first_frame = 0, last_frame = 0;             // Of the associations.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // Mean prior position of associations.
  int level1 = 0;        // First-level cluster it came from (diagnostic).
  double slope_deg = 0;  // Ground heading of `direction` mod 180 deg.
  double sweep_deg = 0;  // Turn of the members' headings along the path (max_sweep_deg).
  double turn_rate_deg_per_100m = 0;  // ... per 100 m of path (max_turn_rate_deg_per_100m).
};

struct DirectionAssociation {
  int64_t frame = 0;
  int vp_index = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  int cluster = 0;                                            // DirectionClusterInfo::id.
  Eigen::Vector3d direction_world = Eigen::Vector3d::Zero();  // This VP's d (diagnostic).
  double angle_deg = 0;  // Between d and its cluster direction.
};

struct DirectionClusterStats {
  int input_vps = 0, missing_prior = 0, forward_kept = 0, level1_clusters = 0, level1_kept = 0,
      window_kept = 0, level2_too_wide = 0, level2_turning = 0, level2_clusters = 0,
      associations_before_interval = 0, associations = 0;
};

struct DirectionClusterResult {
  std::vector<DirectionClusterInfo> clusters;      // Ordered by id.
  std::vector<DirectionAssociation> associations;  // Sorted by frame; <= 1 per frame.
  Eigen::Vector3d up = Eigen::Vector3d::Zero();    // Ground basis used (e1, e2, up right-handed).
  Eigen::Vector3d ground_e1 = Eigen::Vector3d::Zero(), ground_e2 = Eigen::Vector3d::Zero();
  DirectionClusterStats stats;
};

// Runs Algorithm 2 on the VPs of the frames in `prior`. VPs of frames absent from the prior
// are skipped and counted (stats.missing_prior). Throws on bad options or camera.
DirectionClusterResult ClusterDirections(const std::vector<VpObservation>& vps,
                                         const Trajectory& prior, const PinholeCamera& camera,
                                         const DirectionClusterOptions& options);

// V_interval: per cluster, walks its associations in frame order and keeps one when it is at
// least `interval` frames after the last kept one (0 keeps all). Returns the kept rows in frame
// order.
std::vector<DirectionAssociation> DownsampleAssociations(
    const std::vector<DirectionAssociation>& associations, int interval);

}  // namespace jvl::direction
