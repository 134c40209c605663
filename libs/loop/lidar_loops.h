// The LiDAR loop detector: place recognition with the polar height descriptor
// (scan_descriptor.h), geometric verification by IMLS registration of the two scans (the
// registration of lidar_odom, lidar/registration.h) from the descriptor's best yaw or from the
// best yaw near the opposite direction (a street looks much the same both ways round), a bound
// on the trajectory's drift, and temporal consistency over consecutive keyframes, in geometry.
// One of the loop stage's detectors (loop_detect); it never looks at the trajectory's positions
// to find a candidate, only at its path length to skip the keyframes just driven and at its
// motion between consecutive keyframes to check that consecutive loops agree. The proximity
// detector (DetectProximityLoops), here too, does: the same verification on the trajectory's
// nearest earlier keyframe.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/lru_cache.h"
#include "geometry/calibration.h"
#include "geometry/point_cloud.h"
#include "geometry/rigid3.h"
#include "geometry/trajectory.h"
#include "lidar/association.h"
#include "lidar/imls.h"
#include "lidar/preprocess.h"
#include "lidar/registration.h"
#include "lidar/surface.h"
#include "loop/scan_descriptor.h"

namespace jvl::loop {

inline constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

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
  // The coarse pass registers on the match's surface thinned to one point per voxel of this
  // size (m; 0 = every point): its neighbourhoods are coarse_scale times wider.
  double coarse_voxel = 1.0;
  int coarse_samples_per_list = 50;  // ... and with fewer samples (of the same lists).
  double max_residual = 0.08;        // m, RMS IMLS distance after registration.
  int min_correspondences = 300;     // At the last iteration.
  double max_translation = 15.0;     // m between the two scans: a revisit, not a place 30 m on.
  // The trajectory given (a prior or odometry) may drift, but not without bound: the two
  // keyframes must lie within max_prior_offset + max_prior_drift x (path length between them)
  // of each other in it. Rejects a look-alike place far away (repetitive streets).
  double max_prior_offset = 20.0;  // m
  double max_prior_drift = 0.1;    // Fraction of the path length.
  // Accepted when `consistency` consecutive keyframes (this one and the ones before it) have
  // verified matches within consistency_keyframes keyframes of each other's.
  int consistency = 2;
  int consistency_keyframes = 3;
  // ... and agreeing in geometry (see DetectLidarLoops) within these.
  double consistency_m = 1.0;
  double consistency_deg = 3.0;
  // The proximity detector (DetectProximityLoops): candidates are the earlier keyframes (at
  // least min_separation_m back along the path) within proximity_radius_m +
  // proximity_drift x (path length between them) of the query in the trajectory given.
  double proximity_radius_m = 10.0;
  double proximity_drift = 0.02;
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
  kDuplicate = 8,  // Accepted, but an earlier detector closed the query (earlier versions).
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

class LoopScanCache;

// keyframes: the frames to search (increasing) with their poses (only the path length between
// them is used). load_scan(frame): the scan as read (not de-skewed). calibration: cam0_from_velo
// for the preprocessing (the descriptor is computed in the velodyne frame). tick() is called
// once per keyframe described and once per candidate verified (progress). scans: the prepared
// scans of the verification (prepared with these options), shared with the visual detector.
// skip(frame): queries not to verify (closed by a detector run before); the consistency - 1
// keyframes before a query that is verified are verified too (its temporal consistency needs
// them), but only the other queries' candidates are returned.
LoopResult DetectLidarLoops(const Trajectory& keyframes, LoopScanCache& scans,
                            const LidarLoopOptions& options, int threads,
                            const std::function<bool(int64_t)>& skip = nullptr,
                            const std::function<void()>& tick = nullptr);

// The proximity detector (beyond the paper; LiDAR SLAM systems search loop candidates this
// way): the trajectory's nearest earlier keyframe within the proximity bound is the candidate,
// the query's scan is registered on its scan from the trajectory's relative pose (the coarse
// pass, then the normal one), and the LiDAR detector's bounds and temporal consistency decide.
// It closes what a place descriptor cannot: a street driven the other way round on the other
// lane. It relies on the trajectory's positions, so its recall falls with the drift where the
// descriptors' does not. skip(frame): as for DetectLidarLoops.
LoopResult DetectProximityLoops(const Trajectory& keyframes, LoopScanCache& scans,
                                const LidarLoopOptions& options, int threads,
                                const std::function<bool(int64_t)>& skip = nullptr,
                                const std::function<void()>& tick = nullptr);

// The verification shared by both detectors. A keyframe's scan preprocessed as lidar_odom does
// it (cam0 frame) and its surface, as IMLS-SLAM sampling lists: the points registered as the
// query, and the points of the IMLS models registered on ...
struct LoopScan {
  LoopScan(const PointCloud& scan, const Calibration& calibration, const LidarLoopOptions& options);
  lidar::SampledScan samples;
  // The place descriptor of the scan as read (a few kB: made with the preparation, so that the
  // LiDAR detector does not read a prepared scan again).
  ScanDescriptor descriptor;
};
// ... `query` registered on `match` from `initial` = match_from_query: a coarse pass with
// scaled neighbourhoods, then the normal one (as lidar_odom's first pair) ...
lidar::RegistrationResult RegisterLoopScans(const LoopScan& query, const LoopScan& match,
                                            const Rigid3d& initial,
                                            const LidarLoopOptions& options);
// ... or from the best of several starts: each registered at the coarse neighbourhoods, the
// best one (converged without a degenerate direction, then the lower residual; its index in
// *chosen) refined; without a coarse pass (coarse_scale 1) the first start.
lidar::RegistrationResult RegisterLoopScans(const LoopScan& query, const LoopScan& match,
                                            const std::vector<Rigid3d>& initials,
                                            const LidarLoopOptions& options,
                                            size_t* chosen = nullptr);
// ... and its status against the bounds (accepted, registration failed, residual, too far).
LoopStatus RegistrationStatus(const lidar::RegistrationResult& registration,
                              const LidarLoopOptions& options);
// The registration into a candidate: its pose (match_from_query), correspondences, residual,
// convergence and degeneracy, and the status RegistrationStatus gives it.
void TakeRegistration(const lidar::RegistrationResult& registration,
                      const LidarLoopOptions& options, LoopCandidate* candidate);
// Heading of the query relative to the match (about the camera's vertical, left positive; rad).
double RelativeHeading(const Rigid3d& match_from_query);
// Two loops of consecutive queries against each other: loop2 (match_from_query of query2) as
// loop1 predicts it through the trajectory's motion from query1 to query2 and from match1 to
// match2 (world_from_cam poses), as the offset loop2^-1 * predicted (identity when they agree).
Rigid3d LoopDisagreement(const Rigid3d& query1, const Rigid3d& match1, const Rigid3d& loop1,
                         const Rigid3d& query2, const Rigid3d& match2, const Rigid3d& loop2);
// The drift bound: keyframes q and m lie further apart in the trajectory than
// max_prior_offset + max_prior_drift x the path length between them.
bool FarInPrior(const Trajectory& keyframes, const std::vector<double>& path, size_t q, size_t m,
                const LidarLoopOptions& options);

// The prepared scans of the keyframes being verified, each prepared once and kept while it is
// among the `capacity` most recently used (consecutive queries verify against neighbouring
// matches; about 1 MB each on KITTI scans). Both detectors may share one. Thread-safe; a scan
// is prepared outside the cache's lock, once.
class LoopScanCache {
 public:
  LoopScanCache(std::function<PointCloud(int64_t)> load_scan, const Calibration& calibration,
                const LidarLoopOptions& options, size_t capacity = 1024);
  std::shared_ptr<const LoopScan> Get(int64_t frame);
  // The scan of `frame` if it is prepared and kept, else null (nothing is prepared).
  std::shared_ptr<const LoopScan> Find(int64_t frame);
  // Prepares the scans of `frames` (repeats allowed; the first `capacity` distinct ones, so give
  // them in the order they will be needed) on `threads`
  // threads before a verification needs them: each is prepared once, in parallel, instead of
  // two verifications waiting on the same scan.
  void Prepare(const std::vector<int64_t>& frames, int threads);
  PointCloud Load(int64_t frame) const { return load_scan_(frame); }  // As read, not cached.
  const LidarLoopOptions& options() const { return options_; }        // The preparation's.
  const Calibration& calibration() const { return calibration_; }

 private:
  std::function<PointCloud(int64_t)> load_scan_;
  Calibration calibration_;
  LidarLoopOptions options_;
  LruCache<int64_t, LoopScan> cache_;
};

}  // namespace jvl::loop
