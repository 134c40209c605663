// The visual map as an artifact (Sec. 4.1's output, io/visual_io.h): its flat layout, the
// figures visual_assoc reports, the run summary, and the prior pose selection.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "geometry/trajectory.h"
#include "io/visual_io.h"
#include "mapping/visual/map_builder.h"
#include "mapping/visual/visual_map.h"

namespace jvl::mapping {

// Flat artifact layout: good points only (renumbered), all keypoints of every keyframe,
// observations ordered by (keyframe, keypoint), covisibility edges with weight >= min_weight.
io::VisualMapData ExportVisualMap(const VisualMap& map, const Trajectory& prior, int min_weight);

// Rows [first, last) of keypoints/* of each keyframe of the artifact, by frame id (the layout of
// ExportVisualMap: keypoints grouped by keyframe).
std::unordered_map<int64_t, std::pair<size_t, size_t>> KeypointRowsByFrame(
    const io::VisualMapData& data);

// The ORB features of keypoint rows [first, last): the keyframe's features as visual_assoc
// extracted them (the inverse of ExportVisualMap for one keyframe; loop_detect reads them
// instead of extracting ORB again).
vision::OrbFeatures KeyframeFeatures(const io::VisualMapData& data, size_t first, size_t last);

// Figures reported by visual_assoc and checked by the tests.
struct VisualMapStats {
  int keyframes = 0, mappoints = 0, observations = 0, edges = 0;
  double median_points_per_keyframe = 0, min_points_per_keyframe = 0;
  double mean_observations_per_point = 0;
  double median_reprojection_px = 0, p90_reprojection_px = 0;
};
VisualMapStats ComputeStats(const io::VisualMapData& data);

// The prior poses of `frames` (every frame must be in the prior; throws naming the first missing
// frame and `what`).
Trajectory SelectPriorPoses(const Trajectory& prior, const std::vector<int64_t>& frames,
                            const std::string& what);

// Summary JSON: counts, per-keyframe points, reprojection error, keyframe reasons, timings.
nlohmann::json Summarize(const VisualMapResult& result, const VisualMapStats& stats);
// A few human-readable lines of that summary.
std::string FormatSummary(const nlohmann::json& summary);

}  // namespace jvl::mapping
