// Command-line options of lidar_odom: every algorithm parameter of OdometryOptions.
#pragma once

#include <string>

#include "app/tool.h"
#include "lidar/odometry.h"

namespace jvl::tools {

// `deskew`: the --deskew mode (auto, on, off), resolved against the dataset (io::ResolveDeskew);
// `vertical_correction`: auto or an angle, resolved by io::ResolveVerticalCorrection.
void AddLidarOdomFlags(app::Tool& tool, lidar::OdometryOptions* options, std::string* deskew,
                       std::string* vertical_correction);

}  // namespace jvl::tools
