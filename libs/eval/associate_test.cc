#include "eval/associate.h"

#include <gtest/gtest.h>

#include "core/check.h"
#include "eval/test_util.h"

namespace jvl::eval {
namespace {

TEST(Associate, ByFrameReportsMissingAndUnmatched) {
  const PoseSeries gt = testing::StraightLine(10);
  PoseSeries est = testing::MakeSeries(2, 10, [](int64_t) { return Eigen::Matrix4d::Identity(); });
  est = testing::Erase(est, 5);  // Frames 2..11 without 5; 10 and 11 have no ground truth.
  const Association a = Associate(gt, est, {});
  ASSERT_EQ(a.size(), 7u);
  EXPECT_EQ(a.gt_row.front(), 2u);
  EXPECT_EQ(a.est_row.front(), 0u);
  EXPECT_EQ(a.gt_row.back(), 9u);
  EXPECT_EQ(a.gt_missing_frames, std::vector<int64_t>({5}));
  EXPECT_EQ(a.est_unmatched_frames, std::vector<int64_t>({10, 11}));
}

TEST(Associate, ByTimestampNearestWithinMaxDt) {
  const PoseSeries gt = testing::StraightLine(10);  // t = 0.0, 0.1, ..., 0.9
  PoseSeries est;
  for (double t : {0.004, 0.097, 0.102, 0.35, 0.7}) {
    est.frames.push_back(static_cast<int64_t>(est.frames.size()));
    est.poses.push_back(Eigen::Matrix4d::Identity());
    est.timestamps.push_back(t);
  }
  AssociationOptions o;
  o.mode = AssociationMode::kTimestamp;
  o.max_dt = 0.01;
  const Association a = Associate(gt, est, o);
  // 0.097 and 0.102 both pick gt 0.1; the closer (0.102) wins; 0.35 is too far.
  EXPECT_EQ(a.gt_row, std::vector<size_t>({0, 1, 7}));
  EXPECT_EQ(a.est_row, std::vector<size_t>({0, 2, 4}));
  EXPECT_EQ(a.est_unmatched_frames, std::vector<int64_t>({1, 3}));
}

TEST(Associate, NothingMatchesIsAnError) {
  const PoseSeries gt = testing::StraightLine(5);
  const PoseSeries est =
      testing::MakeSeries(100, 3, [](int64_t) { return Eigen::Matrix4d::Identity(); });
  try {
    Associate(gt, est, {}, "est.txt");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("est.txt: no pose matches"), std::string::npos) << e.message();
  }
  PoseSeries no_time = gt;
  no_time.timestamps.clear();
  AssociationOptions o;
  o.mode = AssociationMode::kTimestamp;
  EXPECT_THROW(Associate(gt, no_time, o), Error);
}

}  // namespace
}  // namespace jvl::eval
