// What global_opt takes from the "local" artifact (io/local_io.h): refined keyframes, the saved
// correspondence set L, refined map points and the stored per-keyframe scans, as plain values.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "geometry/trajectory.h"
#include "io/local_io.h"
#include "mapping/global_mapping.h"
#include "optim/joint_problem.h"

namespace jvl::global_opt {

struct LocalInput {
  Trajectory keyframes;                         // refined
  std::vector<optim::ImlsCorrespondence> imls;  // n, c = keyframe rows
  std::vector<Eigen::Vector3d> mappoints;       // refined, visual.h5 rows
  std::vector<lidar::StoredScan> scans;     // one per keyframe
  Trajectory prior;                             // empty if absent
};

LocalInput ToLocalInput(const io::LocalMapData& data);
LocalInput ReadLocalInput(const std::string& path);
// Only the stored scans (for the map export after the optimisation has released its copy).
std::vector<lidar::StoredScan> ReadLocalScans(const std::string& path);

}  // namespace jvl::global_opt
