// Turns the artifacts (visual, local, directions) into the plain global problem input.
#pragma once

#include "io/directions_io.h"
#include "io/visual_io.h"
#include "local_input.h"
#include "mapping/global_mapping.h"

namespace jvl::global_opt {

// Keyframes, map points (refined, else visual's), scans and L come from local; observations
// (keypoint uv + octave) from visual; direction associations with their cluster's d_w. The large
// parts of `local` (scans, L, map points) are moved, not copied.
mapping::GlobalMapInput AssembleGlobalInput(const io::VisualMapData& visual, LocalInput&& local,
                                            const io::DirectionsData* directions);

}  // namespace jvl::global_opt
