// Direction priors of the keyframes (paper Sec. 4.3, Eq. 6; supplement 1.4): which VPs of the
// directions artifact become e_D residuals, and the re-estimation of each cluster's world
// direction d_w from the current keyframe rotations. Plain values; the cost itself is
// jvl::optim's.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <vector>

#include "geometry/camera.h"
#include "geometry/trajectory.h"

namespace jvl::direction {

// A VP of a frame associated with a direction prior d_w (a row of the directions artifact).
struct VpAssociation {
  int64_t frame = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // Pixels; NaN if the VP is at infinity.
  Eigen::Vector3d direction_world = Eigen::Vector3d::UnitZ();
  int32_t cluster = 0;
};

// One e_D residual's data: the VP v of keyframe row `keyframe` and the world direction d_w.
struct VpPrior {
  int64_t keyframe = 0;  // Row of the keyframe trajectory.
  Eigen::Vector2d vp = Eigen::Vector2d::Zero();  // Pixels, finite.
  Eigen::Vector3d direction_world = Eigen::Vector3d::UnitZ();  // Unit.
};

struct DirectionSelection {
  std::vector<VpPrior> priors;
  std::vector<int32_t> clusters;  // Cluster of each prior.
  int64_t not_keyframe = 0;       // Associations of frames that are not keyframes.
  int64_t at_infinity = 0;        // Non-finite VP (skipped: e_D needs a finite v).
};

// Direction priors re-estimated from the current keyframe rotations.
struct DirectionRefit {
  DirectionSelection selection;                   // Inliers with their cluster's new d_w.
  std::map<int32_t, Eigen::Vector3d> directions;  // Cluster -> re-estimated d_w (kept clusters).
  std::map<int32_t, double> change_deg;           // Cluster -> angle(old d_w, new d_w).
  int64_t outliers = 0;           // VPs further than the gate from their cluster's direction.
  int64_t small_cluster_vps = 0;  // VPs of clusters left with < min_support inliers.
};

// One prior per association of a keyframe with a finite VP (a VP at infinity has no pixel v
// for Eq. 6). Throws if a used d_w is not a unit vector.
DirectionSelection SelectDirections(const Trajectory& keyframes,
                                    const std::vector<VpAssociation>& associations);

// Re-estimates d_w of every cluster from the rotations of `keyframes` (rows as in `selection`):
// each VP v of keyframe n gives the world direction R_wn K^-1 v (sign of the old d_w); d_w is
// their mean over the VPs within a gate of max(outlier_deg, 3 sigma) of it, sigma from the
// median angle (iterated to a fixed point; drops the VPs of turn exits and mismatched lines).
// Clusters with fewer than `min_support` inliers are dropped.
DirectionRefit RefitDirections(const Trajectory& keyframes, const PinholeCamera& camera,
                               const DirectionSelection& selection, double outlier_deg,
                               int min_support);

// Median of |v - pi(R_nw d_w)| (pixels) over `priors` at the rows' poses of `keyframes` (NaN if
// empty); d_w is unoriented (as in the cost) and directions parallel to the image plane are
// skipped.
double MedianDirectionError(const Trajectory& keyframes, const PinholeCamera& camera,
                            const std::vector<VpPrior>& priors);

}  // namespace jvl::direction
