#include "mapping/visual/keyframe_rule.h"

#include <gtest/gtest.h>

#include "core/check.h"

namespace jvl::mapping {
namespace {

KeyframeRuleInput Input(int since, int tracked, int reference, bool direction = false) {
  KeyframeRuleInput in;
  in.frames_since_last_keyframe = since;
  in.tracked = tracked;
  in.reference_tracked = reference;
  in.has_direction = direction;
  return in;
}

TEST(KeyframeRule, FirstFrameIsAKeyframe) {
  KeyframeRuleInput in = Input(1, 0, 0);
  in.first_frame = true;
  const KeyframeDecision d = DecideKeyframe(in, KeyframeRuleOptions());
  EXPECT_TRUE(d.keyframe);
  EXPECT_EQ(d.reason, KeyframeReason::kFirst);
}

TEST(KeyframeRule, FourConditions) {
  KeyframeRuleOptions options;
  options.min_frames_between = 3;
  // C4: 80 < 0.9 * 100 -> keyframe when C2 and C3 hold.
  KeyframeDecision d = DecideKeyframe(Input(3, 80, 100), options);
  EXPECT_TRUE(d.keyframe);
  EXPECT_EQ(d.reason, KeyframeReason::kConditions);
  EXPECT_TRUE(d.c1 && d.c2 && d.c3 && d.c4);
  // C4 fails: tracks 95 % of the reference.
  d = DecideKeyframe(Input(3, 95, 100), options);
  EXPECT_FALSE(d.keyframe);
  EXPECT_FALSE(d.c4);
  EXPECT_EQ(d.reason, KeyframeReason::kNone);
  // C2 fails: too soon after the last keyframe.
  d = DecideKeyframe(Input(2, 60, 100), options);
  EXPECT_FALSE(d.keyframe);
  EXPECT_FALSE(d.c2);
  // Exactly 90 % is not "less than 90 %".
  d = DecideKeyframe(Input(5, 90, 100), options);
  EXPECT_FALSE(d.keyframe);
}

TEST(KeyframeRule, StarvedFrameBecomesKeyframe) {
  KeyframeRuleOptions options;
  options.min_frames_between = 2;
  KeyframeDecision d = DecideKeyframe(Input(2, 20, 30), options);  // C3 fails (< 50 tracked).
  EXPECT_TRUE(d.keyframe);
  EXPECT_FALSE(d.c3);
  EXPECT_EQ(d.reason, KeyframeReason::kStarved);
  d = DecideKeyframe(Input(1, 20, 30), options);  // ... but not before C2 holds.
  EXPECT_FALSE(d.keyframe);
}

TEST(KeyframeRule, DirectionFrameIsAlwaysAKeyframe) {
  KeyframeRuleOptions options;
  options.min_frames_between = 5;
  // Neither C2 nor C4 holds, but the frame has a direction association (Sec. 4.1).
  KeyframeDecision d = DecideKeyframe(Input(1, 300, 300, true), options);
  EXPECT_TRUE(d.keyframe);
  EXPECT_EQ(d.reason, KeyframeReason::kDirection);
  EXPECT_FALSE(d.c2);
  EXPECT_FALSE(d.c4);
  // Same frame without the association is not a keyframe.
  EXPECT_FALSE(DecideKeyframe(Input(1, 300, 300, false), options).keyframe);
  // The direction condition can be switched off.
  options.use_directions = false;
  EXPECT_FALSE(DecideKeyframe(Input(1, 300, 300, true), options).keyframe);
}

TEST(KeyframeRule, OptionsAreChecked) {
  KeyframeRuleOptions options;
  options.reference_ratio = 1.5;
  EXPECT_THROW(options.Check(), Error);
  options = KeyframeRuleOptions();
  options.min_frames_between = 0;
  EXPECT_THROW(options.Check(), Error);
}

}  // namespace
}  // namespace jvl::mapping
