// How well a sequence's calibration aligns the LiDAR with the camera, measured on the data
// (`calib_check`, docs/calib_check.md): the LiDAR's depth edges - returns nearer than their
// neighbour on the same laser ring, the outlines of poles, trunks, cars and building corners -
// should fall on edges of the image (the edge-alignment objective of Levinson and Thrun,
// "Automatic Online Calibration of Cameras and Lasers", RSS 2013). The rotation of the
// calibration's camera-LiDAR extrinsic that puts most edge weight on image edges, summed over
// many frames, is the rotation error of the calibration as the data see it. Only the rotation is
// searched: at the depths used (>= 10 m by default) a centimetre of translation moves a point by
// well under a pixel, a tenth of a degree by more than one.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/camera.h"
#include "geometry/point_cloud.h"

namespace jvl::fidelity {

struct EdgeAlignmentOptions {
  // LiDAR depth edges: a return is an edge point when a neighbour on its ring (within these
  // angles in the LiDAR frame) lies at least `min_discontinuity_m` farther; its weight is the
  // square root of that jump, capped at `max_discontinuity_m` (Levinson and Thrun's X_i). The
  // same with the neighbours on the rings above and below, for outlines seen edge-on (a top
  // outline above the sensor's horizontal plane, a bottom one below it): seen from above, the
  // return may lie on a top surface short of the outline, which the camera (ahead of and below
  // the LiDAR) sees shifted by parallax.
  double ring_elevation_deg = 0.1;
  double ring_azimuth_deg = 0.4;
  // The rings above and below lie within this elevation (a horizontal depth edge: the top of a
  // wall or a car); HDL-64: 0.33-0.5 deg apart.
  double ring_spacing_deg = 0.8;
  double min_discontinuity_m = 0.5;
  double max_discontinuity_m = 10;
  // Edge points used: depth in camera 0's frame within [min_depth_m, max_depth_m].
  double min_depth_m = 10;
  double max_depth_m = 80;
  // Image edge fields, one per direction: the gradient across the edge (|d/du| for the LiDAR's
  // vertical outlines, |d/dv| for its horizontal ones; Sobel on the image smoothed with sigma
  // 1 px), saturated as E = g / (g + edge_saturation) so that a faint outline counts about as
  // much as a strong one (else points slide along an outline towards its strongest part), spread
  // across the edge: D(p) = max_q E(q) edge_decay^|p - q| along the row (column); field =
  // mix E + (1 - mix) D, less its mean over a Gaussian of background_sigma_px along the same
  // direction (a point in a busy region gains nothing; only one on an outline does).
  double edge_saturation = 4;
  double edge_decay = 0.9;
  double edge_mix = 1.0 / 3.0;
  double background_sigma_px = 8;
  // Search over rotations about camera 0's x (pitch), y (yaw) and z (roll) axes: a grid within
  // +-search_deg at coarse_step_deg, then a grid of fine_step_deg within one coarse step of the
  // best, refined per axis by a parabola through the best grid point and its neighbours.
  double search_deg = 0.8;
  double coarse_step_deg = 0.1;
  double fine_step_deg = 0.02;
  // Spread of the estimate: the search on the fine grid repeated over frames drawn with
  // replacement (a bootstrap over the frames), this many times, from this seed.
  int bootstrap = 200;
  // Fewer edge points over all frames than this is an error (a handful of outlines fits any
  // rotation; a KITTI frame has about 1000).
  int64_t min_edge_points = 200;
  uint64_t seed = 1;
  void Check() const;
};

// Depth-edge returns of a scan (LiDAR frame) with their weights.
struct DepthEdges {
  // The nearer return moved half way towards its far neighbour's ray (at its own range).
  std::vector<Eigen::Vector3d> points;
  std::vector<double> weights;
  std::vector<uint8_t> horizontal;  // 1: the jump is to the ring above or below.
};
DepthEdges FindDepthEdges(const PointCloud& scan, const EdgeAlignmentOptions& options);

// The image's edge fields (CV_32F, the size of the image, unitless: saturated edges in [0, 1)
// less their local mean): across vertical edges (u) and across horizontal ones (v); `image` is
// 8-bit grey or colour (BGR).
struct EdgeFields {
  cv::Mat across_u, across_v;
};
EdgeFields EdgeField(const cv::Mat& image, const EdgeAlignmentOptions& options);

// One frame of the search: its edge fields and its edge points in camera 0's frame at the
// calibration's extrinsic, those within the depth range and inside the image.
struct AlignmentFrame {
  EdgeFields fields;
  std::vector<Eigen::Vector3d> points;  // camera 0 frame
  std::vector<double> weights;
  std::vector<uint8_t> horizontal;  // 1: a horizontal outline (the rings above / below).
};
// camera: the image's camera index in `calibration` (its intrinsics and offset from camera 0).
AlignmentFrame MakeAlignmentFrame(const PointCloud& scan, const cv::Mat& image,
                                  const Calibration& calibration, int camera,
                                  const EdgeAlignmentOptions& options);

// Sum of weight x field (its direction's) over a frame's edge points with the extrinsic rotated
// by `rotation` (about camera 0's origin: x' = rotation x), projected into the camera; bilinear
// in the field, zero outside the image.
double FrameScore(const AlignmentFrame& frame, const Eigen::Matrix3d& rotation,
                  const PinholeCamera& camera, const Eigen::Vector3d& camera_offset);

struct EdgeAlignmentResult {
  // The rotation to apply to the calibration: cam0_from_velo' = Exp(correction) cam0_from_velo,
  // as a rotation vector in camera 0's frame (deg; x pitch, y yaw, z roll). Its inverse is the
  // calibration's error as the data see it.
  Eigen::Vector3d correction_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d bootstrap_std_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d bootstrap_p05_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d bootstrap_p95_deg = Eigen::Vector3d::Zero();
  // Resamples whose best rotation lies on the fine grid's border (their spread is cut there).
  int bootstrap_at_border = 0;
  // The best coarse rotation lies on the grid's border, or the fine search stopped on its own.
  bool at_search_limit = false;
  // The edge fields under the edge points (unitless), per unit of edge weight over all frames,
  // at calib.txt's extrinsic and at the corrected one; per frame (summed, not divided).
  double score_calibration = 0;
  double score_corrected = 0;
  std::vector<double> frame_score_calibration, frame_score_corrected;
  int frames = 0;
  int64_t edge_points = 0;
};
EdgeAlignmentResult AlignEdges(const std::vector<AlignmentFrame>& frames,
                               const PinholeCamera& camera, const Eigen::Vector3d& camera_offset,
                               const EdgeAlignmentOptions& options, int threads);

// The result as the calib_check artifact's body (schemas/calib_check.schema.json) without
// "frames", "camera" and "vertical_correction_deg", which the caller adds.
nlohmann::json EdgeAlignmentJson(const EdgeAlignmentResult& result,
                                 const EdgeAlignmentOptions& options);

// calibration with its extrinsic rotated by a correction of AlignEdges.
Calibration CorrectedCalibration(const Calibration& calibration,
                                 const Eigen::Vector3d& correction_deg);

}  // namespace jvl::fidelity
