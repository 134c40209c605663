// A LiDAR scan as read from disk: points in the sensor (or cam0) frame with reflectance.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace jvl {

struct PointCloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<float> intensity;  // Empty or same length as points.
  size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
};

}  // namespace jvl
