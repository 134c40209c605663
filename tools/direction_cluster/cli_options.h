// Command-line options of direction_cluster: Algorithm 2's thresholds and V_interval.
#pragma once

#include <string>

#include "app/tool.h"
#include "direction/direction_cluster.h"

namespace jvl::tools {

// `up` takes the world up vector as given ("x,y,z" or "auto"), parsed by the caller.
void AddDirectionClusterFlags(app::Tool& tool, direction::DirectionClusterOptions* options,
                              std::string* up);

}  // namespace jvl::tools
