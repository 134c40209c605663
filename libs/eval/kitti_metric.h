// The KITTI odometry benchmark metric (devkit evaluate_odometry.cpp, Geiger et al. 2012):
// segments of 100, 200, ..., 800 m of ground-truth path starting every 10 frames; the error of a
// segment is inverse(est_first^-1 est_last) * (gt_first^-1 gt_last); t_err = |translation| /
// length, r_err = rotation angle / length; the sequence score is the mean over all segments.
#pragma once

#include <cstdint>
#include <vector>

#include "eval/metrics.h"

namespace jvl::eval {

struct KittiOptions {
  std::vector<double> lengths = {100, 200, 300, 400, 500, 600, 700, 800};  // m
  int step_frames = 10;  // Segment start every step_frames ground-truth rows.
  void Check() const;
};

struct KittiSegment {
  int64_t first_frame = 0, last_frame = 0;
  double length_m = 0;
  double t_err = 0;  // |t| / length (ratio; * 100 for %).
  double r_err = 0;  // rad / m.
};

struct KittiLengthRow {
  double length_m = 0;
  int64_t count = 0;
  // Means over the segments of this length; NaN when there is none.
  double t_rel_percent = 0, r_rel_deg_per_100m = 0;
};

struct KittiResult {
  std::vector<KittiSegment> segments;
  std::vector<KittiLengthRow> per_length;
  // NaN when there is no segment (path shorter than the shortest length): undefined, not 0.
  double t_rel_percent = 0;       // Mean t_err * 100 over all segments.
  double r_rel_deg_per_100m = 0;  // Mean r_err * 180 / pi * 100 over all segments.
};

KittiResult ComputeKitti(const PairedPoses& paired, const std::vector<double>& gt_distances,
                         const KittiOptions& options);

// Scores of a list of segments (the devkit's average over all segments it is given, so several
// sequences' segments pooled give the devkit's multi-sequence score).
KittiResult SummarizeSegments(std::vector<KittiSegment> segments,
                              const std::vector<double>& lengths);

// 180 / pi * 100: rad/m -> deg/100 m, as the devkit's plots and kitti-odom-eval print it.
double RadPerMetreToDegPer100m(double r);

}  // namespace jvl::eval
