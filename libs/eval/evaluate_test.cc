#include "eval/evaluate.h"

#include <gtest/gtest.h>

#include "core/check.h"
#include "eval/report.h"
#include "eval/test_util.h"

namespace jvl::eval {
namespace {

using testing::Pose;

TEST(Evaluate, Sim3UndoesScaleAndRigidOffset) {
  const PoseSeries gt = testing::Curve(300, 0.01);
  PoseSeries est = gt;
  const Eigen::Matrix4d offset = Pose(testing::Yaw(0.5), Eigen::Vector3d(10, 0, -4));
  for (auto& p : est.poses) {
    p.block<3, 1>(0, 3) *= 0.5;  // Monocular scale.
    p = offset * p;
  }
  EvalOptions o;
  o.alignment = Alignment::kSim3;
  const SequenceEval r = EvaluateSequence(gt, est, o, "s");
  EXPECT_NEAR(r.alignment.scale, 2.0, 1e-10);
  EXPECT_LT(r.ape.translation_stats.max, 1e-9);
  EXPECT_LT(r.ape.rotation_stats.max, 1e-5);
  EXPECT_LT(r.kitti.t_rel_percent, 1e-9);
  EXPECT_GT(r.kitti.segments.size(), 0u);
  o.alignment = Alignment::kSE3;
  EXPECT_EQ(EvaluateSequence(gt, est, o).alignment.scale, 1.0);
}

TEST(Evaluate, OriginAlignmentRemovesARigidOffset) {
  const PoseSeries gt = testing::Curve(50, 0.03);
  PoseSeries est = testing::Erase(gt, 0);  // Starts at frame 1 and misses frame 15.
  est = testing::Erase(est, 15);
  const Eigen::Matrix4d offset = Pose(testing::Yaw(-1.0), Eigen::Vector3d(3, 1, 2));
  for (auto& p : est.poses) p = offset * p;
  EvalOptions o;
  EXPECT_GT(EvaluateSequence(gt, est, o).ape.translation_stats.rmse, 1.0);
  o.alignment = Alignment::kOrigin;
  const SequenceEval r = EvaluateSequence(gt, est, o);
  EXPECT_EQ(r.origin_frame, 1);
  EXPECT_EQ(r.frames_matched, 48);
  EXPECT_EQ(r.gt_missing_frames, std::vector<int64_t>({15}));
  EXPECT_LT(r.ape.translation_stats.max, 1e-12);
  EXPECT_EQ(r.rpe.translation_stats.count, 46);
}

TEST(Evaluate, PooledAndMeanOfSequencesDiffer) {
  EvalOptions o;
  std::vector<SequenceEval> seqs;
  for (double scale : {1.1, 1.3}) {
    const PoseSeries gt = testing::StraightLine(scale == 1.1 ? 1000 : 300);
    PoseSeries est = gt;
    for (auto& p : est.poses) p.block<3, 1>(0, 3) *= scale;
    seqs.push_back(EvaluateSequence(gt, est, o, scale == 1.1 ? "a" : "b"));
  }
  const double ta = seqs[0].kitti.t_rel_percent, tb = seqs[1].kitti.t_rel_percent;
  const double na = seqs[0].kitti.segments.size(), nb = seqs[1].kitti.segments.size();
  const EstimateEval e = CombineSequences("x", seqs, o.kitti);
  EXPECT_NEAR(e.kitti_mean_t_rel_percent, 0.5 * (ta + tb), 1e-12);
  EXPECT_NEAR(e.kitti_pooled.t_rel_percent, (ta * na + tb * nb) / (na + nb), 1e-10);
  EXPECT_EQ(e.frames_matched, 1300);
  const nlohmann::json j = EstimateToJson(e, o);
  EXPECT_EQ(j["sequences"].size(), 2u);
  EXPECT_EQ(j["kitti"]["segments"].get<int64_t>(), na + nb);
  const std::string table = FormatTable({e}, o);
  EXPECT_NE(table.find("x / b"), std::string::npos) << table;
  EXPECT_NE(FormatMarkdown({e}, o).find("| 100 |"), std::string::npos);
}

TEST(Evaluate, BadOptionsAndInputsFailClearly) {
  EvalOptions o;
  o.rpe.delta = 0;
  const PoseSeries gt = testing::StraightLine(5);
  EXPECT_THROW(EvaluateSequence(gt, gt, o), Error);
  o = EvalOptions();
  o.alignment = Alignment::kSim3;
  PoseSeries two = testing::StraightLine(2);
  EXPECT_THROW(EvaluateSequence(two, two, o), Error);
}

}  // namespace
}  // namespace jvl::eval
