#include "sim/preview.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/check.h"

namespace jvl::sim {

cv::Mat ScanTopView(const PointCloud& scan, double lidar_height, double half_extent,
                    double resolution) {
  JVL_CHECK(half_extent > 0 && resolution > 0, "top view extent and resolution must be positive");
  const int n = static_cast<int>(std::lround(2 * half_extent / resolution));
  cv::Mat img(n, n, CV_8U, cv::Scalar(255));
  // Draw low points first so that walls and objects stay visible on top of the road.
  std::vector<size_t> order(scan.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return scan.points[a].z() < scan.points[b].z(); });
  for (size_t i : order) {
    const Eigen::Vector3d& p = scan.points[i];
    const int col = static_cast<int>(std::floor((half_extent - p.y()) / resolution));
    const int row = static_cast<int>(std::floor((half_extent - p.x()) / resolution));
    if (row < 0 || col < 0 || row >= n || col >= n) continue;
    const double h = p.z() + lidar_height;  // Height above the road.
    // Road-level points light grey, anything standing on it dark (walls, poles, cars, plants).
    const int v = h < 0.25 ? 185 : static_cast<int>(std::clamp(110.0 - 12.0 * h, 0.0, 110.0));
    for (int dr = 0; dr < 2 && row + dr < n; ++dr) {
      for (int dc = 0; dc < 2 && col + dc < n; ++dc) {
        uint8_t& px = img.at<uint8_t>(row + dr, col + dc);
        px = static_cast<uint8_t>(std::min<int>(px, v));
      }
    }
  }
  const cv::Point c(n / 2, n / 2);
  cv::rectangle(img, c + cv::Point(-8, -20), c + cv::Point(8, 20), cv::Scalar(0), 1);
  return img;
}

}  // namespace jvl::sim
