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

}  // namespace jvl::mapping
