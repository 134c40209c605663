// The LiDAR loop detector: place recognition with the polar height descriptor
// (scan_descriptor.h), geometric verification by IMLS registration of the two scans (the
// registration of lidar_odom, lidar/registration.h) from the descriptor's best yaw and, if that
// fails, from the best yaw near the opposite direction (a street looks much the same both ways
// round), a bound on the trajectory's drift, and temporal consistency over consecutive
// keyframes. One of the loop stage's detectors (loop_detect); it never looks at the trajectory's
// positions to find a candidate, only at its path length to skip the keyframes just driven.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/point_cloud.h"
#include "geometry/rigid3.h"
#include "geometry/trajectory.h"
#include "lidar/association.h"
#include "lidar/preprocess.h"
#include "lidar/registration.h"
#include "lidar/surface.h"
#include "loop/scan_descriptor.h"

namespace jvl::loop {

struct LidarLoopOptions {
  ScanDescriptorOptions descriptor;
  // Candidates: earlier keyframes at least this far back along the trajectory's path (m) ...
  double min_separation_m = 50.0;
  // ... the `ring_key_candidates` nearest by ring key, of which the verify_candidates nearest
  // by descriptor distance below max_descriptor_distance are verified; the accepted one with
  // the lowest residual is kept.
  int ring_key_candidates = 10;
  int verify_candidates = 3;
  double max_descriptor_distance = 0.35;
  // Verification: the query scan registered on the candidate's (lidar_odom's preprocessing,
  // surface and IMLS registration), from the descriptor's yaw; a coarse pass with every
  // neighbourhood scaled by coarse_scale first (no translation is known).
  lidar::PreprocessOptions preprocess;
  lidar::SurfaceOptions surface;
  lidar::AssociationOptions association;
  lidar::RegistrationOptions registration;
  double coarse_scale = 4.0;
  double max_residual = 0.08;     // m, RMS IMLS distance after registration.
  int min_correspondences = 300;  // At the last iteration.
  double max_translation = 15.0;  // m between the two scans: a revisit, not a place 30 m on.
  // The trajectory given (a prior or odometry) may drift, but not without bound: the two
  // keyframes must lie within max_prior_offset + max_prior_drift x (path length between them)
  // of each other in it. Rejects a look-alike place far away (repetitive streets).
  double max_prior_offset = 20.0;  // m
  double max_prior_drift = 0.1;    // Fraction of the path length.
  // Accepted when `consistency` consecutive keyframes (this one and the ones before it) have
  // verified matches within consistency_keyframes keyframes of each other's.
  int consistency = 2;
  int consistency_keyframes = 3;
  double consistency_yaw_deg = 30.0;  // ... and relative headings within this of each other's.
  void Check() const;
};

enum class LoopStatus : int32_t {
  kAccepted = 0,
  kRegistrationFailed = 1,  // Too few correspondences, no convergence or degenerate.
  kResidual = 2,            // Registered, but the residual or correspondences fail the bounds.
  kTooFar = 3,              // Registered more than max_translation apart.
  kInconsistent = 4,        // Verified, but the keyframes before it do not agree.
  kFarInPrior = 5,          // The trajectory puts the two keyframes too far apart.
  kFewInliers = 6,          // Visual: too few 3D-2D matches agree on one relative pose.
  kDisagree = 7,            // Visual: the scan registration moved far from the image's pose.
  kDuplicate = 8,           // Accepted, but the LiDAR detector closed the same query already.
};
const char* ToString(LoopStatus status);

// A 3D-2D match of a visual loop (a PnP inlier): a point of the match keyframe (its cam0 frame,
// depth from its scan) seen at match_uv in the match image and at query_uv in the query image.
struct LoopPoint {
  Eigen::Vector3d p_match = Eigen::Vector3d::Zero();
  Eigen::Vector2d match_uv = Eigen::Vector2d::Zero(), query_uv = Eigen::Vector2d::Zero();
  int match_octave = 0, query_octave = 0;  // ORB pyramid levels.
};

// A verified candidate (accepted or not): kept in the artifact for inspection.
struct LoopCandidate {
  int64_t query = 0;  // Dataset frames: the later keyframe and its match.
  int64_t match = 0;
  std::string detector = "lidar";
  double ring_key_distance = 0;
  // LiDAR: descriptor distance (0 = identical); visual: bag-of-words score (1 = identical).
  double descriptor_distance = 0;
  double yaw_rad = 0;        // The descriptor's yaw of the query relative to the match.
  Rigid3d match_from_query;  // cam0 frames; from the registration.
  int correspondences = 0;
  int inliers = 0;  // Visual: 3D-2D matches consistent with the image's relative pose ...
  std::vector<LoopPoint> points;  // ... (the inliers themselves).
  double residual = 0;            // m.
  bool converged = false;
  bool degenerate = false;
  LoopStatus status = LoopStatus::kRegistrationFailed;
};

struct LoopResult {
  std::vector<int64_t> keyframes;         // Frames searched, in order.
  std::vector<LoopCandidate> candidates;  // By query; status kAccepted = a loop.
};

// keyframes: the frames to search (increasing) with their poses (only the path length between
// them is used). load_scan(frame): the scan as read (not de-skewed). calibration: cam0_from_velo
// for the preprocessing (the descriptor is computed in the velodyne frame). tick() is called
// once per keyframe described and once per candidate verified (progress).
LoopResult DetectLidarLoops(const Trajectory& keyframes,
                            const std::function<PointCloud(int64_t)>& load_scan,
                            const Calibration& calibration, const LidarLoopOptions& options,
                            int threads, const std::function<void()>& tick = nullptr);

// The verification shared by both detectors. The scan of a keyframe preprocessed as lidar_odom
// does it (cam0 frame) with its surface ...
lidar::ScanSurface LoopSurface(const PointCloud& scan, const Calibration& calibration,
                               const LidarLoopOptions& options);
// ... `query` registered on the model of `match` from `initial` = match_from_query: a coarse pass
// with scaled neighbourhoods, then the normal one (as lidar_odom's first pair) ...
lidar::RegistrationResult RegisterLoopScans(const lidar::ScanSurface& query,
                                            const lidar::ScanSurface& match, const Rigid3d& initial,
                                            const LidarLoopOptions& options);
// ... and its status against the bounds (accepted, registration failed, residual, too far).
LoopStatus RegistrationStatus(const lidar::RegistrationResult& registration,
                              const LidarLoopOptions& options);
// Heading of the query relative to the match (about the camera's vertical, left positive; rad).
double RelativeHeading(const Rigid3d& match_from_query);
// Path length along the keyframes' trajectory at every keyframe.
std::vector<double> PathLengths(const Trajectory& keyframes);
// The drift bound: keyframes q and m lie further apart in the trajectory than
// max_prior_offset + max_prior_drift x the path length between them.
bool FarInPrior(const Trajectory& keyframes, const std::vector<double>& path, size_t q, size_t m,
                const LidarLoopOptions& options);

}  // namespace jvl::loop
