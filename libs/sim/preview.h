// Quick-look images of simulated data for documentation and inspection.
#pragma once

#include <opencv2/core.hpp>

#include "geometry/point_cloud.h"

namespace jvl::sim {

// Bird's-eye view of a scan in the velodyne frame (x forward = up in the image, y left = left):
// white background, points darker the higher they are above the sensor's road level (z = -h).
// half_extent metres around the sensor, `resolution` metres per pixel.
cv::Mat ScanTopView(const PointCloud& scan, double lidar_height, double half_extent = 50.0,
                    double resolution = 0.1);

}  // namespace jvl::sim
