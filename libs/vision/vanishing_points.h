// Vanishing points of one image (Sec. 4.3 and Supplement 1.4, step 1 of the paper): up to
// `max_vps` directions d (unit, camera frame) such that many image line segments point at the
// image of d. Work is done on the Gaussian sphere of the calibrated camera, so a VP at or near
// infinity (parallel image lines) is an ordinary direction with d_z ~ 0.
//
// Method: sequential MSAC. Each round draws pairs of segments, intersects their interpretation
// planes (d = n_i x n_j), scores every remaining segment by the angle between its
// interpretation plane and the plane through its midpoint ray and d, keeps the best hypothesis,
// refines it on its inliers by least squares (eigenvector start + Gauss-Newton on the same
// angular residual), and removes the inliers before the next round.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <vector>

#include "geometry/camera.h"
#include "vision/line_segments.h"

namespace jvl {

struct VpOptions {
  int max_vps = 3;                      // At most this many VPs per image (paper: 3).
  double inlier_threshold_deg = 1.5;    // Max angular residual of an inlier segment.
  int ransac_iterations = 300;          // Segment pairs drawn per VP.
  uint64_t seed = 42;                   // RNG seed (same seed, same image -> same result).
  int min_inliers = 8;                  // A VP needs at least this many inlier segments.
  int refine_iterations = 3;            // Inlier re-selection + least-squares rounds.
  double min_separation_deg = 5.0;      // A new VP must be this far from the earlier ones.
  double forward_max_angle_deg = 45.0;  // is_forward only within this angle of the optical axis.
  void Check() const;
};

struct VanishingPoint {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // Unit, camera frame, z >= 0.
  // Pixel position K d / d_z; NaN when the VP is at infinity (d_z < kInfinityDz).
  Eigen::Vector2d uv = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  int inliers = 0;
  double residual_deg = 0;  // RMS angular residual of the inlier segments.
  double score = 0;         // MSAC support: sum over inliers of length * (1 - (r / threshold)^2).
  bool is_forward = false;  // Closest to the optical axis (within forward_max_angle_deg).
};

// |d_z| below this counts as "at infinity" (the pixel would be > 1e6 focal lengths away).
constexpr double kInfinityDz = 1e-6;

struct VpResult {
  std::vector<VanishingPoint> vps;  // In order of detection (largest support first).
  std::vector<LineSegment> segments;
  std::vector<int> segment_vp;  // Per segment: index into vps, or -1.
  int forward_index = -1;       // Index into vps of the forward VP, or -1.
};

struct VpDetectOptions {
  LineSegmentOptions segments;
  VpOptions vp;
  void Check() const {
    segments.Check();
    vp.Check();
  }
};

// VPs from given segments (pixels of `camera`). Fewer than 2 segments give no VPs.
VpResult EstimateVanishingPoints(const std::vector<LineSegment>& segments,
                                 const PinholeCamera& camera, const VpOptions& options);

// Segments from `image`, then EstimateVanishingPoints. An image without lines gives no VPs.
VpResult DetectVanishingPoints(const cv::Mat& image, const PinholeCamera& camera,
                               const VpDetectOptions& options);

// Angle (rad) between the segment's interpretation plane and the plane through its midpoint ray
// and direction d: 0 when the segment points exactly at the VP of d.
double SegmentVpResidual(const LineSegment& segment, const PinholeCamera& camera,
                         const Eigen::Vector3d& d);

// Pixel of direction d (NaN if at infinity) and the canonical sign (z >= 0).
Eigen::Vector2d DirectionToPixel(const Eigen::Vector3d& d, const PinholeCamera& camera);
Eigen::Vector3d CanonicalDirection(const Eigen::Vector3d& d);

}  // namespace jvl
