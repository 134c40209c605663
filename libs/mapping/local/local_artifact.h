// Local mapping's input and output as artifacts (io/visual_io.h in, io/local_io.h out): the one
// place where the stage's plain values meet the on-disk layouts.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/trajectory.h"
#include "io/local_io.h"
#include "io/visual_io.h"
#include "mapping/local/local_mapping.h"

namespace jvl::mapping {

// The visual observations of the artifact (keypoint pixel position and octave per observation).
std::vector<optim::VisualObservation> VisualObservations(const io::VisualMapData& visual);

// From the visual artifact; the initial poses are `prior` at the keyframe frames (every keyframe
// frame must be in it). Observations carry the keypoint's pixel position and octave.
LocalMappingInput MakeLocalMappingInput(const io::VisualMapData& visual, const Trajectory& prior,
                                        const std::string& prior_name);

// The "local" artifact layout; `prior` is stored as the full prior trajectory.
io::LocalMapData ExportLocalMap(const LocalMappingInput& input, const LocalMappingResult& result,
                                const Trajectory& prior, const nlohmann::json& summary);
// The same, consuming the result's correspondences and scans (left empty) as they are copied:
// the artifact's flat arrays then replace them instead of adding to the peak memory (local_map on
// a 4500-frame drive: 3.4 million correspondences and 22.5 million scan points, 0.8 GB). The
// poses, map points and stats stay.
io::LocalMapData ExportLocalMap(const LocalMappingInput& input, LocalMappingResult&& result,
                                const Trajectory& prior, const nlohmann::json& summary);

}  // namespace jvl::mapping
