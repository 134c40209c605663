// The visual loop detector of the paper (supplement 1.3: ORB-SLAM2's place recognition, Mur-Artal
// and Tardos, IEEE T-RO 2017, Sec. V-A/B), on the keyframes of loop_detect:
//
// * Every keyframe image becomes a bag-of-words vector (vocabulary.h) of its ORB features.
// * Candidates of a query keyframe: the earlier keyframes at least lidar.min_separation_m back
//   along the trajectory's path that share words with it (inverted index), keeping those with at
//   least min_common_ratio x the largest number of shared words and a score no lower than the
//   query's lowest score against its own neighbours (the keyframes just before it: ORB-SLAM2's
//   covisible keyframes). Each candidate forms a group with its neighbours (group_keyframes
//   either side); the groups' accumulated scores keep those within min_group_ratio of the best.
// * Temporal consistency: a group is verified once `consistency` consecutive query keyframes have
//   overlapping groups.
// * Geometric verification: ORB matches of the two images within the same vocabulary node (ratio
//   test), the match keyframe's keypoints lifted to 3D with the depth of its LiDAR scan, the query
//   pose from PnP + RANSAC with at least min_inliers inliers, refined by registering the two scans
//   (lidar_loops.h, the LiDAR detector's bounds), which must stay within max_disagreement of the
//   image's pose; the trajectory's drift bound as for the LiDAR detector.
#pragma once

#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/point_cloud.h"
#include "geometry/trajectory.h"
#include "loop/lidar_loops.h"
#include "loop/vocabulary.h"
#include "vision/orb_features.h"

namespace jvl::loop {

struct VisualLoopOptions {
  vision::OrbOptions orb;         // Features of each keyframe image.
  int camera = 0;                 // The camera of the images (loop_detect --camera).
  int group_keyframes = 2;        // Neighbours either side: a candidate's group; the query's.
  double min_common_ratio = 0.8;  // Of the largest number of words shared with the query.
  double min_group_ratio = 0.75;  // Of the best group's accumulated score.
  int consistency = 3;            // Consecutive query keyframes with overlapping groups.
  // Matching: within a vocabulary node `match_level` levels below the root, Hamming distance up to
  // max_hamming and below ratio x the second best.
  int match_level = 2;
  int max_hamming = 50;
  double ratio = 0.75;
  // Depth of a match keypoint: the nearest LiDAR returns projected within depth_window_px (at
  // least 2 within 5 % of the nearest), up to max_depth_m.
  double depth_window_px = 4.0;
  double max_depth_m = 60.0;
  // PnP + RANSAC.
  double max_reprojection_px = 3.0;
  int ransac_iterations = 300;
  int min_inliers = 30;
  // The scan registration from the image's pose must stay this close to it.
  double max_disagreement_m = 1.0;
  double max_disagreement_deg = 5.0;
  // Points stored for the global optimisation: inliers within this many sigmas (the pyramid
  // level's scale, px) of their query pixel at the registered pose.
  double point_max_error_sigmas = 2.0;
  // The separation along the path, registration bounds and the trajectory's drift bound: the
  // LiDAR detector's fields (min_separation_m, preprocess, surface, association, registration,
  // coarse_scale, max_residual, min_correspondences, max_translation, max_prior_offset,
  // max_prior_drift), one set for every detector.
  LidarLoopOptions lidar;
  void Check() const;
};

// A keyframe image as the detector keeps it.
struct VisualKeyframe {
  std::vector<vision::OrbKeypoint> keypoints;
  std::vector<vision::Descriptor> descriptors;
  std::vector<int32_t> nodes;  // Vocabulary node at match_level of each descriptor.
  BowVector bow;
};
VisualKeyframe DescribeImage(const cv::Mat& image, const Vocabulary& vocabulary,
                             const VisualLoopOptions& options);
// The same from features already extracted (e.g. the visual map's keypoints of the keyframe).
VisualKeyframe DescribeFeatures(vision::OrbFeatures features, const Vocabulary& vocabulary,
                                const VisualLoopOptions& options);

// keyframes: the frames to search (increasing) with their poses (only the path length between
// them and the drift bound use them). features_of(frame): the ORB features of camera 0's image
// (extracted with options.orb, or the visual map's); scans: the scans (prepared with
// options.lidar), shared with the LiDAR detector. tick() once per keyframe described and once
// per candidate verified.
LoopResult DetectVisualLoops(const Trajectory& keyframes,
                             const std::function<vision::OrbFeatures(int64_t)>& features_of,
                             LoopScanCache& scans, const Vocabulary& vocabulary,
                             const VisualLoopOptions& options, int threads,
                             const std::function<void()>& tick = nullptr);

// One geometric verification (exposed for tests): match_from_query of `query` against `match`
// (both described; dataset frames query_frame and match_frame), with the match keyframe's scan
// for depth and both scans for the registration, from `scans` (prepared with options.lidar;
// only when the images agree on a pose).
LoopCandidate VerifyVisualCandidate(const VisualKeyframe& query, const VisualKeyframe& match,
                                    int64_t query_frame, int64_t match_frame, LoopScanCache& scans,
                                    const VisualLoopOptions& options);

}  // namespace jvl::loop
