#include "mapping/visual/keyframe_rule.h"

#include "core/check.h"

namespace jvl::mapping {

void KeyframeRuleOptions::Check() const {
  JVL_CHECK(min_frames_between >= 1, "keyframes: min_frames_between must be >= 1");
  JVL_CHECK(min_tracked >= 0, "keyframes: min_tracked must be >= 0");
  JVL_CHECK(reference_ratio > 0 && reference_ratio <= 1,
            "keyframes: reference_ratio must be in (0, 1]");
}

const char* ToString(KeyframeReason reason) {
  switch (reason) {
    case KeyframeReason::kNone:
      return "none";
    case KeyframeReason::kFirst:
      return "first";
    case KeyframeReason::kDirection:
      return "direction";
    case KeyframeReason::kConditions:
      return "conditions";
    case KeyframeReason::kStarved:
      return "starved";
  }
  return "unknown";
}

KeyframeDecision DecideKeyframe(const KeyframeRuleInput& in, const KeyframeRuleOptions& options) {
  KeyframeDecision d;
  d.c1 = true;
  d.c2 = in.frames_since_last_keyframe >= options.min_frames_between;
  d.c3 = in.tracked >= options.min_tracked;
  d.c4 = in.tracked < options.reference_ratio * in.reference_tracked;
  if (in.first_frame) {
    d.reason = KeyframeReason::kFirst;
  } else if (options.use_directions && in.has_direction) {
    d.reason = KeyframeReason::kDirection;
  } else if (d.c1 && d.c2 && d.c3 && d.c4) {
    d.reason = KeyframeReason::kConditions;
  } else if (d.c2 && !d.c3) {
    d.reason = KeyframeReason::kStarved;
  }
  d.keyframe = d.reason != KeyframeReason::kNone;
  return d;
}

}  // namespace jvl::mapping
