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
  int64_t keyframe = 0;                                        // Row of the keyframe trajectory.
  Eigen::Vector2d vp = Eigen::Vector2d::Zero();                // Pixels, finite.
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

// The same per image axis: (median |u error|, median |v error|), NaN if empty.
Eigen::Vector2d MedianAbsDirectionError(const Trajectory& keyframes, const PinholeCamera& camera,
                                        const std::vector<VpPrior>& priors);

// Lag-1 correlation of the errors v - pi(R_nw d_w) of consecutive priors of the same cluster
// (`clusters` as in DirectionSelection; consecutive in keyframe order, whatever the gap): 1 - sum
// |e_i - e_{i-1}|^2 / (2 sum |e_i - mean of its cluster|^2), pooled over the clusters and both
// image axes, clamped to [0, 0.9]; 0 with fewer than 3 priors. The VPs of neighbouring keyframes
// come from the same edges, so their errors are not independent.
double DirectionErrorCorrelation(const Trajectory& keyframes, const PinholeCamera& camera,
                                 const std::vector<VpPrior>& priors,
                                 const std::vector<int32_t>& clusters);

// A vanishing direction of a frame as a unit ray in its camera (vps artifact; any VP, possibly
// at infinity in the image).
struct VpRay {
  int64_t frame = 0;
  Eigen::Vector3d ray = Eigen::Vector3d::UnitZ();
};

// The vertical direction prior (beyond the paper): per keyframe the VP closest to the world's
// up direction, which every keyframe of the drive shares (vertical edges of buildings, poles,
// signs), so that it ties roll and pitch along the whole drive, across turns.
struct VerticalSelection {
  std::vector<int64_t> rows;          // Keyframe rows with an inlier vertical VP.
  std::vector<Eigen::Vector3d> rays;  // Their rays (camera frame, unit).
  Eigen::Vector3d direction = Eigen::Vector3d::UnitY();  // Robust mean in the world (up).
  // From the median angle of the inliers to it (2D Gaussian), times `inflation`.
  double sigma_deg = 0;
  // Lag-1 correlation of consecutive inliers' errors (mean over the two tangent axes, in
  // [0, 0.9]) and the AR(1) effective-sample-size inflation of sigma, sqrt((1 + rho) / (1 - rho)):
  // the errors of neighbouring keyframes come from the same edges and are not independent.
  double rho = 0;
  double inflation = 1;
  int64_t candidates = 0;  // Keyframes with a VP within max_angle_deg of up.
  int64_t outliers = 0;    // Candidates outside the gate.
  // Per row of `rows`: the angle of R_wn ray from `direction` in its tangent plane (deg, the
  // two axes of a fixed basis).
  std::vector<Eigen::Vector2d> errors_deg;
};

// How far a sequence of per-frame errors (deg, two axes; frames ascending) wanders slowly, beyond
// what its frame-to-frame noise explains. After removing the mean: the white covariance W is
// sum (e_i - e_{i-1})(e_i - e_{i-1})^T / (2 (n - 1)) (the uncorrelated part); m_i is the centred
// moving mean over the samples within +-half_window frames of sample i (count c_i); the slow
// covariance is mean_i (m_i m_i^T - W (1 / c_i - 1 / n)), white noise's share in such a mean of
// de-meaned samples taken out. `low_frequency_deg` is the square root of its diagonal (per
// axis, clamped at 0) and `slow_deg` of its largest eigenvalue: the slow error along the
// direction it is largest in, whatever the axes. Fewer than 3 samples: zeros.
struct SlowError {
  Eigen::Vector2d white_deg = Eigen::Vector2d::Zero();
  Eigen::Vector2d low_frequency_deg = Eigen::Vector2d::Zero();
  double slow_deg = 0;
};
SlowError MeasureSlowError(const std::vector<int64_t>& frames,
                           const std::vector<Eigen::Vector2d>& errors_deg, int half_window);

// `up_world` is the world's up direction as the keyframes see it (e.g. minus the y axis of the
// first camera, as direction_cluster takes it). Candidates: per keyframe the ray with the
// smallest angle to R_nw up, if below max_angle_deg; then the robust mean of R_wn ray with the
// gate max(outlier_deg, 3 sigma) of RefitDirections. sigma_deg is at least min_sigma_deg before
// the inflation for correlated errors.
VerticalSelection SelectVertical(const Trajectory& keyframes, const std::vector<VpRay>& rays,
                                 const Eigen::Vector3d& up_world, double max_angle_deg,
                                 double outlier_deg, double min_sigma_deg);

}  // namespace jvl::direction
