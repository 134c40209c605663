// Reader of the "local" artifact (schema "local" v1, written by local_map) limited to what
// global_opt needs: refined keyframes, the saved correspondence set L, refined map points and the
// stored per-keyframe scans. It reads the layout agreed between the stages through io::H5Reader;
// the shared reader io/local_io.h replaces it once it exists.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "geometry/trajectory.h"
#include "mapping/global_mapping.h"
#include "optim/joint_problem.h"

namespace jvl::global_opt {

struct LocalInput {
  Trajectory keyframes;                               // refined
  std::vector<optim::ImlsCorrespondence> imls;        // n, c = keyframe rows
  std::vector<Eigen::Vector3d> mappoints;             // refined, visual.h5 rows
  std::vector<mapping::KeyframeScan> scans;           // one per keyframe
  Trajectory prior;                                   // empty if absent
};

LocalInput ReadLocalInput(const std::string& path);

}  // namespace jvl::global_opt
