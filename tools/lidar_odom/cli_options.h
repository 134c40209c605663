// Command-line options of lidar_odom: every algorithm parameter of OdometryOptions.
#pragma once

#include "app/tool.h"
#include "lidar/odometry.h"

namespace jvl::tools {

void AddLidarOdomFlags(app::Tool& tool, lidar::OdometryOptions* options);

}  // namespace jvl::tools
