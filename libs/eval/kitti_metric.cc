#include "eval/kitti_metric.h"

#include <limits>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "eval/pose_series.h"

namespace jvl::eval {

void KittiOptions::Check() const {
  JVL_CHECK(!lengths.empty(), "KITTI metric: no segment lengths");
  for (double l : lengths) JVL_CHECK(l > 0, "KITTI metric: segment length " << l << " <= 0");
  JVL_CHECK(step_frames >= 1, "KITTI metric: step " << step_frames << " < 1");
}

double RadPerMetreToDegPer100m(double r) { return r / M_PI * 180.0 * 100.0; }

KittiResult ComputeKitti(const PairedPoses& paired, const std::vector<double>& gt_distances,
                         const KittiOptions& options) {
  options.Check();
  std::vector<KittiSegment> segments;
  const size_t step = static_cast<size_t>(options.step_frames);
  for (size_t first = 0; first < paired.size(); first += step) {
    for (double length : options.lengths) {
      // lastFrameFromSegmentLength(): the first row whose distance exceeds dist[first] + length.
      const auto it = std::upper_bound(gt_distances.begin() + first, gt_distances.end(),
                                       gt_distances[first] + length);
      if (it == gt_distances.end()) continue;  // Sequence not long enough.
      const size_t last = static_cast<size_t>(it - gt_distances.begin());
      if (!paired.has_est[first] || !paired.has_est[last]) continue;
      const Eigen::Matrix4d gt_delta = paired.gt[first].inverse() * paired.gt[last];
      const Eigen::Matrix4d est_delta = paired.est[first].inverse() * paired.est[last];
      const Eigen::Matrix4d error = est_delta.inverse() * gt_delta;
      KittiSegment s;
      s.first_frame = paired.frames[first];
      s.last_frame = paired.frames[last];
      s.length_m = length;
      s.r_err = DevkitRotationAngle(error) / length;
      s.t_err = TranslationNorm(error) / length;
      segments.push_back(s);
    }
  }
  return SummarizeSegments(std::move(segments), options.lengths);
}

KittiResult SummarizeSegments(std::vector<KittiSegment> segments,
                              const std::vector<double>& lengths) {
  // No segment (a path shorter than the shortest length): the score is undefined, not 0.
  constexpr double kUndefined = std::numeric_limits<double>::quiet_NaN();
  KittiResult r;
  r.t_rel_percent = r.r_rel_deg_per_100m = kUndefined;
  double t_sum = 0, r_sum = 0;
  for (const KittiSegment& s : segments) t_sum += s.t_err, r_sum += s.r_err;
  if (!segments.empty()) {
    const double n = static_cast<double>(segments.size());
    r.t_rel_percent = t_sum / n * 100.0;
    r.r_rel_deg_per_100m = RadPerMetreToDegPer100m(r_sum / n);
  }
  for (double length : lengths) {
    KittiLengthRow row;
    row.length_m = length;
    row.t_rel_percent = row.r_rel_deg_per_100m = kUndefined;
    double t = 0, rr = 0;
    for (const KittiSegment& s : segments) {
      if (s.length_m != length) continue;
      ++row.count;
      t += s.t_err;
      rr += s.r_err;
    }
    if (row.count > 0) {
      row.t_rel_percent = t / static_cast<double>(row.count) * 100.0;
      row.r_rel_deg_per_100m = RadPerMetreToDegPer100m(rr / static_cast<double>(row.count));
    }
    r.per_length.push_back(row);
  }
  r.segments = std::move(segments);
  return r;
}

}  // namespace jvl::eval
