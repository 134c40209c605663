// Prior pose selection and the run summary of visual_assoc.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/trajectory.h"
#include "mapping/map_builder.h"
#include "mapping/visual_map.h"

namespace jvl::mapping {

// The prior poses of `frames` (every frame must be in the prior; throws naming the first missing
// frame and `what`).
Trajectory SelectPriorPoses(const Trajectory& prior, const std::vector<int64_t>& frames,
                            const std::string& what);

// Summary JSON: counts, per-keyframe points, reprojection error, keyframe reasons, timings.
nlohmann::json Summarize(const VisualMapResult& result, const VisualMapStats& stats);
// A few human-readable lines of that summary.
std::string FormatSummary(const nlohmann::json& summary);

}  // namespace jvl::mapping
