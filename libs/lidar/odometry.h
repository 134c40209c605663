// The tracking odometry (paper Sec. 4.1 and supplement 1.1): each scan is preprocessed,
// sampled as in IMLS-SLAM and registered against the IMLS surface of the last N scans
// (--scan-map-size, the paper's N), starting from a constant-velocity prediction.
//
//   Odometry odom(calib.cam0_from_velo, options, threads);
//   for (frame : frames) { OdometryFrame f = odom.ProcessScan(scan, frame); ... }
//
// Failure is data, not an exception: an empty or unusable scan keeps the motion-model pose and
// is flagged in the frame's diagnostics, with a logged warning.
#pragma once

#include <cstdint>
#include <vector>

#include "geometry/point_cloud.h"
#include "geometry/rigid3.h"
#include "lidar/association.h"
#include "lidar/imls.h"
#include "lidar/preprocess.h"
#include "lidar/registration.h"
#include "lidar/surface.h"

namespace jvl::lidar {

// The odometry's preprocessing: PreprocessOptions' defaults, except that the small objects are
// kept. IMLS-SLAM and the paper's odometry remove them; kept, they made the registration more
// accurate on the real KITTI excerpt and on every simulated drive measured, at 16-18 % more time
// per scan (docs/lidar_odom.md, "Small objects").
inline PreprocessOptions OdometryPreprocessDefaults() {
  PreprocessOptions p;
  p.remove_small_objects = false;
  return p;
}

struct OdometryOptions {
  PreprocessOptions preprocess = OdometryPreprocessDefaults();
  SurfaceOptions surface;
  AssociationOptions association;  // sampling (s = 100: up to 900 points) and Eq. (2)
  RegistrationOptions registration;
  int scan_map_size = 10;  // N: scans kept in the model.
  bool deskew = false;     // Constant-velocity de-skewing from the point azimuths.
  // Second scan (no motion estimate yet): a coarse registration first runs with the search
  // radius, kernel h, max distance and robust scale multiplied by this (1 = off).
  double initial_search_scale = 4.0;
  void Check() const;
};

// How a frame's pose was obtained (stored per frame in the artifact).
enum class FrameStatus : int32_t {
  kOk = 0,
  kFirstFrame = 1,   // Defines the world frame (identity).
  kDegenerate = 2,   // Registered; unobservable directions kept from the motion model.
  kMotionModel = 3,  // Too few points or correspondences: constant-velocity pose.
};
const char* ToString(FrameStatus status);

struct FrameDiagnostics {
  FrameStatus status = FrameStatus::kOk;
  int iterations = 0;
  double residual = 0;  // RMS IMLS distance at the last iteration (m).
  int correspondences = 0;
  double time_ms = 0;                                         // Whole ProcessScan.
  double preprocess_ms = 0, surface_ms = 0, register_ms = 0;  // Its main stages.
  bool degenerate = false;  // Any fallback to the motion model (partial or full).
  bool converged = false;
  int64_t points_after_filter = 0;
  int64_t non_finite_points = 0;  // Dropped NaN/inf points of the input scan.
  int samples = 0;
  double min_eigenvalue = 0;
};

struct OdometryFrame {
  int64_t frame = 0;
  Rigid3d world_from_cam;
  FrameDiagnostics diagnostics;
};

class Odometry {
 public:
  Odometry(const Rigid3d& cam0_from_velo, const OdometryOptions& options, int threads);

  // Registers the next scan (velodyne frame, any number of points, may contain NaN).
  // non_finite_dropped: points the reader already dropped (added to the diagnostics).
  // scan_time_offset: the scan's time minus the frame's, in frame periods
  // (io::Dataset::ScanTimeOffsetInFrames); with de-skewing on, the scan is moved to the frame
  // time with the same constant-velocity motion (PreprocessedScan::time_offset).
  OdometryFrame ProcessScan(const PointCloud& velo_scan, int64_t frame,
                            int64_t non_finite_dropped = 0, double scan_time_offset = 0);

  const ImlsModel& model() const { return model_; }
  const std::vector<OdometryFrame>& frames() const { return frames_; }

 private:
  Rigid3d PredictMotion() const;  // prev_from_cur of the constant-velocity model.
  // Registration from the prediction, with the coarse pass of the second scan.
  RegistrationResult Track(const ScanSurface& surface, const Rigid3d& predicted,
                           int* samples) const;
  RegistrationResult Register(const ScanSurface& surface, const Rigid3d& predicted,
                              const AssociationOptions& association,
                              const RegistrationOptions& options, int* samples) const;
  void UpdateModel(int64_t frame, const ScanSurface& surface, const Rigid3d& world_from_cam);
  // De-skewing of the first two scans, which have no motion before them: once the second is
  // registered raw, both are de-skewed with the motion between them, the first is put back into
  // the model and the second registered again.
  RegistrationResult RedoFirstPair(const PreprocessedScan& second, const RegistrationResult& raw,
                                   ScanSurface* surface, int* samples);

  Rigid3d cam0_from_velo_;
  OdometryOptions options_;
  int threads_;
  ImlsModel model_;
  std::vector<OdometryFrame> frames_;
  PreprocessedScan first_scan_;  // Kept until the second scan when de-skewing.
};

}  // namespace jvl::lidar
