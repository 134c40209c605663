// Builds the visual map of Sec. 4.1 from ORB features and prior poses. Each frame's pose is
// predicted from the prior's motion since the previous frame and, with track_pose (beyond the
// paper: the prior's registration glitches would otherwise break the tracks), refined by a
// motion-only estimate on the matched map points as ORB-SLAM2's tracking does; it is used to
//  1. match the points of the local map by projection (tracking),
//  2. decide whether the frame is a keyframe (keyframe_rule.h, incl. direction frames),
//  3. for keyframes: add the tracked observations, triangulate new points against the most recent
//     keyframes under the epipolar constraint, fuse the new points into those keyframes, and
//     cull recent points that are rarely found (ORB-SLAM2 LocalMapping, without local BA).
// Finish() refines every point with the poses fixed (structure only) and drops outlier
// observations.
#pragma once

#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "geometry/trajectory.h"
#include "mapping/visual/keyframe_rule.h"
#include "mapping/visual/visual_map.h"
#include "vision/guided_matching.h"
#include "vision/orb_features.h"
#include "vision/triangulation.h"

namespace jvl::mapping {

struct VisualMapOptions {
  vision::OrbOptions orb;
  vision::ProjectionMatchOptions projection;
  vision::EpipolarMatchOptions epipolar;
  vision::TriangulationOptions triangulation;
  KeyframeRuleOptions keyframe;
  int local_keyframes = 10;          // Keyframes whose points are projected into a frame.
  int triangulation_neighbors = 5;   // Recent keyframes matched with a new keyframe.
  double min_baseline_ratio = 0.01;  // Baseline / median depth below which a pair is skipped.
  double min_view_cos = 0.5;         // Points seen > 60 deg off their mean direction skip.
  int min_observations = 3;          // Culling: keyframes needed once cull_after_keyframes passed.
  int cull_after_keyframes = 2;      // Keyframes after creation before the observation test.
  double min_found_ratio = 0.25;     // Culling: found / visible.
  bool refine_points = true;         // Structure-only refinement in Finish().
  double max_final_chi2 = 5.991;     // Observations beyond this (x level variance) are dropped.
  // Tracking gate: a projection match is kept only if the point reprojects within this bound
  // (x level variance) of the keypoint; 0 disables the gate.
  double track_chi2 = 5.991;
  // Points gaining observations in a keyframe are refined (poses fixed) and their observations
  // beyond max_final_chi2 dropped at once, not only in Finish().
  bool refine_on_insert = true;
  // Observations are aligned to the point's reference patch (patch_align.h) before use.
  bool align_patches = true;
  // Observations whose patch does not align (NCC below align.min_ncc, or it drifts) are not
  // added: they are most often a different surface point with a similar descriptor (repeated
  // lane dashes, paving joints and window corners along the epipolar lines of a camera moving
  // forward). docs/visual_assoc.md has the measurements behind the default.
  bool require_alignment = true;
  vision::PatchAlignOptions align;
  int min_covisibility_weight = 15;  // Edges kept in the artifact (ORB-SLAM2 threshold).
  // Pose tracking (docs/visual_assoc.md "Pose tracking"): a frame's pose is predicted as the
  // previous frame's pose times the prior's motion between the two, and refined from the
  // projection matches (vision::RefinePose, the camera centre tied to the prediction by
  // pose.center_sigma). The refined pose replaces the prediction only where the two disagree by
  // more than the refinement's own noise on a correct prior (track_min_rotation_deg or
  // track_min_translation_m: the prior has a registration glitch there), within
  // track_max_rotation_deg / track_max_translation_m, with at least track_min_inliers inliers;
  // the points are then matched again at the refined pose. Elsewhere the prior's motion is kept:
  // it is locally far more precise than a monocular estimate. false: every frame takes the
  // prior's pose (the paper).
  bool track_pose = true;
  int track_min_inliers = 40;
  double track_min_inlier_gain = 1.2;
  double track_min_rotation_deg = 0.15;
  double track_min_translation_m = 0.1;
  double track_max_rotation_deg = 3.0;
  double track_max_translation_m = 1.0;
  vision::PoseRefinementOptions pose{4, 10, 5.991, 2.447746830680, 0.05};
  void Check() const;
};

// What happened to one frame.
struct FrameReport {
  int64_t frame = 0;
  int keypoints = 0;
  int candidates = 0;  // Local map points predicted inside the frame.
  int tracked = 0;     // Of those, matched.
  bool keyframe = false;
  KeyframeReason reason = KeyframeReason::kNone;
  int new_points = 0;  // Triangulated (keyframes only).
  int fused = 0;       // Extra observations of new points in neighbour keyframes.
  int culled = 0;
  bool pose_refined = false;                      // track_pose: the refinement was used.
  int pose_inliers = 0, predicted_inliers = 0;    // Matches within pose.chi2: refined / predicted.
  double correction_deg = 0, correction_m = 0;    // Refined pose against the prediction.
  double pose_change_deg = 0, pose_change_m = 0;  // Pose used against the prior's (this frame).
  double ms = 0;                                  // Association time (excluding ORB extraction).
};

class VisualMapBuilder {
 public:
  // `threads`: the patch alignments of one step (a keyframe's tracked keypoints, the fused
  // matches in one neighbour) run in parallel; the result does not depend on it.
  VisualMapBuilder(const PinholeCamera& camera, const VisualMapOptions& options, int threads = 1);
  // Frames must come in increasing frame order.
  FrameReport AddFrame(int64_t frame, const Rigid3d& world_from_cam, vision::OrbFeatures features,
                       bool has_direction);
  // Refines points, drops outlier observations and returns the map (builder is then empty).
  VisualMap Finish();
  const VisualMap& map() const { return map_; }

 private:
  std::vector<int> LocalPoints() const;
  // Matches the local points at *cam_from_world (refined there with track_pose); per keypoint
  // the map point or -1.
  std::vector<int> Track(const vision::OrbFeatures& features, Rigid3d* cam_from_world,
                         FrameReport* report);
  // Projection matches at a pose: (point, keypoint) pairs and the points predicted in view.
  std::vector<std::pair<int, int>> MatchAt(const vision::OrbFeatures& features,
                                           const vision::KeypointGrid& grid,
                                           const std::vector<int>& local,
                                           const Rigid3d& cam_from_world,
                                           std::vector<int>* predicted) const;
  int ReferenceTracked(const std::vector<int>& match) const;
  int CreateNewPoints(int keyframe);                                 // map_points.cc
  int FusePoints(int keyframe, const std::vector<int>& new_points);  // map_points.cc
  int CullRecentPoints(int keyframe);                                // map_points.cc
  std::vector<int> NeighbourKeyframes(int keyframe) const;           // map_points.cc
  // Refines a point over its observations and drops those beyond max_final_chi2 (the point is
  // removed below 2). Returns the number of observations dropped.
  int RefineAndCheck(int point);  // map_points.cc
  // Takes the reference patch of a point from one of its keypoints (map_points.cc).
  void SetPatch(int point, int keyframe, int keypoint);
  // Where a keypoint aligns with the point's reference patch (map_points.cc), computed without
  // changing the map so that the alignments of distinct points can run in parallel;
  // ApplyAlignment then moves the keypoint and returns false if the alignment failed (the
  // keypoint is left as detected), true if it moved or alignment is off or not possible (no
  // reference patch or level images).
  struct Alignment {
    bool ok = true;      // false: the alignment failed
    bool moved = false;  // uv holds the aligned keypoint position
    Eigen::Vector2f uv = Eigen::Vector2f::Zero();
  };
  Alignment ComputeAlignment(int point, int keyframe, int keypoint) const;
  bool ApplyAlignment(const Alignment& a, int keyframe, int keypoint);
  // ComputeAlignment of each (point, keypoint) pair in `keyframe`, on threads_ threads.
  std::vector<Alignment> ComputeAlignments(const std::vector<std::pair<int, int>>& pairs,
                                           int keyframe) const;

  VisualMapOptions options_;
  int threads_ = 1;
  VisualMap map_;
  std::vector<int> recent_points_;  // Created within the last keyframes; subject to culling.
  int64_t last_frame_ = -1;
  Rigid3d last_prior_, last_pose_;  // world_from_cam of the previous frame: prior / used.
  bool corrected_ = false;          // A refinement has moved the poses off the prior.
  int frames_since_keyframe_ = 0;
  bool first_ = true;
};

// Runs the builder over the frames of `poses`: images are loaded and ORB features extracted in
// parallel batches (threads), association is sequential. `load_image(frame)` returns the image,
// `direction_frames` lists frames with a direction association (may be empty), `on_frame` (may be
// empty) is called after each frame.
struct VisualMapResult {
  VisualMap map;
  std::vector<FrameReport> frames;
  std::vector<double> orb_ms;  // Per frame ORB extraction time.
  bool track_pose = false;     // VisualMapOptions::track_pose of the run.
};
VisualMapResult BuildVisualMap(const PinholeCamera& camera, const Trajectory& poses,
                               const std::vector<int64_t>& direction_frames,
                               const std::function<cv::Mat(int64_t)>& load_image,
                               const VisualMapOptions& options, int threads,
                               const std::function<void(const FrameReport&)>& on_frame = {});

}  // namespace jvl::mapping
