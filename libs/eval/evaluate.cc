#include "eval/evaluate.h"

#include <Eigen/LU>
#include <limits>

#include "core/check.h"

namespace jvl::eval {

void EvalOptions::Check() const {
  association.Check();
  rpe.Check();
  kitti.Check();
}

namespace {

// Matched positions (est, gt) for the Umeyama fit, in ground-truth order.
void MatchedPositions(const PoseSeries& gt, const PoseSeries& est, const Association& a,
                      std::vector<Eigen::Vector3d>* est_xyz, std::vector<Eigen::Vector3d>* gt_xyz) {
  for (size_t k = 0; k < a.size(); ++k) {
    est_xyz->push_back(est.poses[a.est_row[k]].block<3, 1>(0, 3));
    gt_xyz->push_back(gt.poses[a.gt_row[k]].block<3, 1>(0, 3));
  }
}

// Both series relative to their first matched pose (gt_0^-1 gt_i, est_0^-1 est_i).
void ToOrigin(const Association& a, PoseSeries* gt, PoseSeries* est) {
  const Eigen::Matrix4d gt0_inv = gt->poses[a.gt_row.front()].inverse();
  const Eigen::Matrix4d est0_inv = est->poses[a.est_row.front()].inverse();
  for (Eigen::Matrix4d& p : gt->poses) p = gt0_inv * p;
  for (Eigen::Matrix4d& p : est->poses) p = est0_inv * p;
}

}  // namespace

SequenceEval EvaluateSequence(const PoseSeries& gt_in, const PoseSeries& est_in,
                              const EvalOptions& options, const std::string& name,
                              const std::string& est_name) {
  options.Check();
  gt_in.Check("ground truth");
  est_in.Check(est_name);
  const Association a = Associate(gt_in, est_in, options.association, est_name);
  SequenceEval r;
  r.name = name;
  r.gt_poses = static_cast<int64_t>(gt_in.size());
  r.est_poses = static_cast<int64_t>(est_in.size());
  r.frames_matched = static_cast<int64_t>(a.size());
  r.est_unmatched_frames = a.est_unmatched_frames;
  r.gt_missing_frames = a.gt_missing_frames;

  PoseSeries gt = gt_in, est = est_in;
  if (options.alignment == Alignment::kOrigin || options.origin_first) {
    ToOrigin(a, &gt, &est);
    r.origin_frame = gt.frames[a.gt_row.front()];
    r.world_from_origin = gt_in.poses[a.gt_row.front()];
  }
  if (options.alignment == Alignment::kSE3 || options.alignment == Alignment::kSim3) {
    std::vector<Eigen::Vector3d> est_xyz, gt_xyz;
    MatchedPositions(gt, est, a, &est_xyz, &gt_xyz);
    r.alignment = Umeyama(est_xyz, gt_xyz, options.alignment == Alignment::kSim3);
  }

  PairedPoses& p = r.paired;
  p.frames = gt.frames;
  p.gt = gt.poses;
  p.est.assign(gt.size(), Eigen::Matrix4d::Identity());
  p.has_est.assign(gt.size(), 0);
  for (size_t k = 0; k < a.size(); ++k) {
    p.est[a.gt_row[k]] = r.alignment.Apply(est.poses[a.est_row[k]]);
    p.has_est[a.gt_row[k]] = 1;
  }
  const std::vector<double> dist = TrajectoryDistances(p.gt);
  r.ape = ComputeApe(p);
  r.ape_components = ComputeApeComponents(p);
  r.rpe = ComputeRpe(p, dist, options.rpe);
  r.kitti = ComputeKitti(p, dist, options.kitti);
  return r;
}

EstimateEval CombineSequences(std::string label, std::vector<SequenceEval> sequences,
                              const KittiOptions& kitti_options) {
  JVL_CHECK(!sequences.empty(), "estimate '" << label << "': no sequences evaluated");
  EstimateEval e;
  e.label = std::move(label);
  std::vector<const std::vector<double>*> ape_t, ape_r, rpe_t, rpe_p, rpe_r;
  std::vector<const ApeComponents*> components;
  std::vector<KittiSegment> segments;
  double t_sum = 0, r_sum = 0, scored = 0;
  for (const SequenceEval& s : sequences) {
    e.frames_matched += s.frames_matched;
    ape_t.push_back(&s.ape.translation_m);
    ape_r.push_back(&s.ape.rotation_deg);
    components.push_back(&s.ape_components);
    rpe_t.push_back(&s.rpe.translation_m);
    rpe_p.push_back(&s.rpe.translation_percent);
    rpe_r.push_back(&s.rpe.rotation_deg);
    segments.insert(segments.end(), s.kitti.segments.begin(), s.kitti.segments.end());
    if (!s.kitti.segments.empty()) {  // sequences without a segment have no score
      t_sum += s.kitti.t_rel_percent;
      r_sum += s.kitti.r_rel_deg_per_100m;
      ++scored;
    }
  }
  e.ape_translation = PoolStats(ape_t);
  e.ape_rotation = PoolStats(ape_r);
  e.ape_components = PoolApeComponents(components);
  e.rpe_translation = PoolStats(rpe_t);
  e.rpe_percent = PoolStats(rpe_p);
  e.rpe_rotation = PoolStats(rpe_r);
  e.kitti_pooled = SummarizeSegments(std::move(segments), kitti_options.lengths);
  e.kitti_mean_t_rel_percent =
      scored > 0 ? t_sum / scored : std::numeric_limits<double>::quiet_NaN();
  e.kitti_mean_r_rel_deg_per_100m =
      scored > 0 ? r_sum / scored : std::numeric_limits<double>::quiet_NaN();
  e.sequences = std::move(sequences);
  return e;
}

}  // namespace jvl::eval
