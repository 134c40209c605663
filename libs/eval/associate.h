// Which estimated pose belongs to which ground-truth pose.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "eval/pose_series.h"

namespace jvl::eval {

enum class AssociationMode { kFrame, kTimestamp };
AssociationMode ParseAssociationMode(const std::string& name);  // frame|timestamp
std::string ToString(AssociationMode mode);

struct AssociationOptions {
  AssociationMode mode = AssociationMode::kFrame;
  double max_dt = 0.01;  // s; kTimestamp only: largest accepted |t_est - t_gt|.
  void Check() const;
};

struct Association {
  // Matched rows, sorted by gt_row (both strictly increasing).
  std::vector<size_t> gt_row;
  std::vector<size_t> est_row;
  // Estimated poses that found no partner, and ground-truth frames inside the span of the
  // matched frames that have no estimate (a dropped frame). Reported, not fatal.
  std::vector<int64_t> est_unmatched_frames;
  std::vector<int64_t> gt_missing_frames;
  size_t size() const { return gt_row.size(); }
};

// Frame mode pairs equal frame indices; timestamp mode pairs each estimate with the nearest
// ground-truth timestamp within max_dt, keeping the closer one when two estimates pick the same
// ground-truth pose. Throws (naming est_name) when nothing matches.
Association Associate(const PoseSeries& gt, const PoseSeries& est,
                      const AssociationOptions& options, const std::string& est_name = "estimate");

}  // namespace jvl::eval
