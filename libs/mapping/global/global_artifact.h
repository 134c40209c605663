// Global optimisation's input from the artifacts (local, visual, directions) and the stored
// scans: the one place where the stage's plain values meet the on-disk layouts.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "geometry/trajectory.h"
#include "io/directions_io.h"
#include "io/local_io.h"
#include "io/visual_io.h"
#include "lidar/association.h"
#include "mapping/global/global_mapping.h"
#include "optim/joint_problem.h"

namespace jvl::mapping {

// What the global optimisation takes from the "local" artifact: refined keyframes, the saved
// correspondence set L, refined map points and the stored per-keyframe scans.
struct StoredLocalMap {
  Trajectory keyframes;                         // refined
  std::vector<optim::ImlsCorrespondence> imls;  // n, c = keyframe rows
  std::vector<Eigen::Vector3d> mappoints;       // refined, visual.h5 rows
  std::vector<lidar::StoredScan> scans;         // one per keyframe
  Trajectory prior;                             // empty if absent
};

StoredLocalMap ToStoredLocalMap(const io::LocalMapData& data);
StoredLocalMap ReadStoredLocalMap(const std::string& path);
// Only the stored scans (for the map export after the optimisation has released its copy).
std::vector<lidar::StoredScan> ReadStoredScans(const std::string& path);

// Keyframes, map points (refined, else visual's), scans and L come from local; observations
// (keypoint uv + octave) from visual; direction associations with their cluster's d_w. The large
// parts of `local` (scans, L, map points) are moved, not copied.
GlobalMapInput AssembleGlobalInput(const io::VisualMapData& visual, StoredLocalMap&& local,
                                   const io::DirectionsData* directions);

}  // namespace jvl::mapping
