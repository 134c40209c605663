// Command-line options of lidar_odom: every algorithm parameter of OdometryOptions.
#pragma once

#include <CLI/CLI.hpp>

#include "lidar/odometry.h"

namespace jvl::lidar_odom {

void AddOdometryOptions(CLI::App& cli, lidar::OdometryOptions& options);

}  // namespace jvl::lidar_odom
