// One call that scores an estimated trajectory against ground truth: association, alignment,
// APE, RPE and the KITTI segment metric; and the combination over several sequences.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "eval/align.h"
#include "eval/associate.h"
#include "eval/kitti_metric.h"
#include "eval/metrics.h"
#include "eval/pose_series.h"

namespace jvl::eval {

struct EvalOptions {
  // none: poses as given. origin: both trajectories relative to their first matched pose.
  // se3 / sim3: Umeyama on the matched positions (evo's -a / -as).
  Alignment alignment = Alignment::kNone;
  // With se3/sim3: first express both relative to the first matched pose (kitti-odom-eval's
  // procedure; the fitted transform absorbs it, so scores change only by rounding).
  bool origin_first = false;
  AssociationOptions association;
  RpeOptions rpe;
  KittiOptions kitti;
  void Check() const;
};

struct SequenceEval {
  std::string name;
  int64_t gt_poses = 0, est_poses = 0, frames_matched = 0;
  std::vector<int64_t> est_unmatched_frames;  // Estimates without ground truth.
  std::vector<int64_t> gt_missing_frames;     // Ground-truth frames without estimate (in span).
  int64_t origin_frame = -1;                  // Ground-truth frame used as origin, or -1.
  // The ground-truth pose at origin_frame (identity without one): maps `paired` back into the
  // ground truth's own world frame, so that plots of several estimates share one frame.
  Eigen::Matrix4d world_from_origin = Eigen::Matrix4d::Identity();
  Similarity alignment;  // Applied to the (origin-relative) estimate.
  PairedPoses paired;    // After alignment; all ground-truth rows.
  ApeResult ape;
  ApeComponents ape_components;  // The APE along the path and about the camera axes.
  RpeResult rpe;
  KittiResult kitti;
};

// Throws (naming est_name) when nothing matches or alignment is degenerate.
SequenceEval EvaluateSequence(const PoseSeries& gt, const PoseSeries& est,
                              const EvalOptions& options, const std::string& name = "",
                              const std::string& est_name = "estimate");

// One estimate over one or more sequences.
struct EstimateEval {
  std::string label;
  std::vector<SequenceEval> sequences;
  int64_t frames_matched = 0;
  // Statistics of the per-frame (APE) and per-pair (RPE) errors of all sequences together.
  ErrorStats ape_translation, ape_rotation, rpe_translation, rpe_percent, rpe_rotation;
  // Signed APE components of all sequences together (see ApeComponents).
  ApeComponentStats ape_components;
  // KITTI pooled over all segments of all sequences (the devkit's multi-sequence score) ...
  KittiResult kitti_pooled;
  // ... and the mean of the per-sequence scores (what many papers print).
  double kitti_mean_t_rel_percent = 0, kitti_mean_r_rel_deg_per_100m = 0;
};
EstimateEval CombineSequences(std::string label, std::vector<SequenceEval> sequences,
                              const KittiOptions& kitti_options);

}  // namespace jvl::eval
