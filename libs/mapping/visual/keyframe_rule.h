// Keyframe decision of Sec. 4.1: the four conditions of ORB-SLAM (Mur-Artal et al. 2015,
// Sec. V-E; kept in ORB-SLAM2, Mur-Artal & Tardos 2017) OR a valid direction association.
//
// Adaptation to a pipeline whose poses come from a prior (no tracking thread, no relocalisation,
// local mapping run synchronously):
//   C1 ">= 20 frames since the last relocalisation": there is no relocalisation -> always true.
//   C2 "local mapping idle or >= 20 frames since the last keyframe": mapping runs to completion
//      before the next frame, so it is idle whenever a frame arrives; C2 holds once
//      min_frames_between frames have passed since the last keyframe.
//   C3 ">= 50 tracked points": ORB-SLAM would be lost below this; with a prior pose the frame is
//      still usable, and a map that tracks so few points needs new ones, so a frame failing C3
//      (when C2 holds) becomes a keyframe ("starved") instead of being rejected.
//   C4 "tracks < 90 % of the points of the reference keyframe".
//   keyframe = first frame OR direction OR (C1 AND C2 AND C3 AND C4) OR (C2 AND NOT C3).
#pragma once

namespace jvl::mapping {

struct KeyframeRuleOptions {
  int min_frames_between = 1;    // C2: frames since the last keyframe (1 = every frame may be one).
  int min_tracked = 50;          // C3.
  double reference_ratio = 0.9;  // C4.
  bool use_directions = true;    // Frames with a direction association are always keyframes.
  void Check() const;
};

struct KeyframeRuleInput {
  bool first_frame = false;
  int frames_since_last_keyframe = 0;
  int tracked = 0;            // Map points matched in the current frame.
  int reference_tracked = 0;  // Points of the reference keyframe seen by >= 3 keyframes.
  bool has_direction = false;
};

enum class KeyframeReason { kNone, kFirst, kDirection, kConditions, kStarved };
const char* ToString(KeyframeReason reason);

struct KeyframeDecision {
  bool keyframe = false;
  KeyframeReason reason = KeyframeReason::kNone;
  bool c1 = true, c2 = false, c3 = false, c4 = false;
};

KeyframeDecision DecideKeyframe(const KeyframeRuleInput& input, const KeyframeRuleOptions& options);

}  // namespace jvl::mapping
