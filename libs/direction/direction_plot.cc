#include "direction/direction_plot.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "direction/ground.h"

namespace jvl::direction {
namespace {

// Distinct colours (BGR), cycled over cluster ids.
cv::Scalar ClusterColour(int id) {
  static constexpr int kPalette[][3] = {{31, 119, 180},  {255, 127, 14},  {44, 160, 44},
                                        {214, 39, 40},   {148, 103, 189}, {140, 86, 75},
                                        {227, 119, 194}, {188, 189, 34},  {23, 190, 207}};
  const auto& c = kPalette[id % 9];
  return cv::Scalar(c[2], c[1], c[0]);
}

}  // namespace

cv::Mat RenderTopView(const Trajectory& prior, const DirectionClusterResult& result,
                      const TopViewOptions& options) {
  GroundFrame g;
  g.up = result.up;
  g.e1 = result.ground_e1;
  g.e2 = result.ground_e2;
  std::vector<Eigen::Vector2d> xy;
  for (const auto& p : prior.world_from_cam) xy.push_back(g.Project(p.translation()));
  Eigen::Vector2d lo(0, 0), hi(1, 1);
  if (!xy.empty()) {
    lo = hi = xy.front();
    for (const auto& p : xy) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  // Keep the shorter side at least half the longer one so a straight road stays readable.
  const double longest = std::max(1.0, (hi - lo).maxCoeff());
  const Eigen::Vector2d pad = ((0.5 * longest - (hi - lo).array()).max(0.0) / 2).matrix();
  lo -= pad;
  hi += pad;
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(1.0);
  const int inner = options.size_px - 2 * options.margin_px;
  const double scale = inner / extent.maxCoeff();
  const int w = int(std::ceil(extent.x() * scale)) + 2 * options.margin_px;
  const int h = int(std::ceil(extent.y() * scale)) + 2 * options.margin_px;
  cv::Mat image(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
  auto pixel = [&](const Eigen::Vector2d& p) {
    return cv::Point2d(options.margin_px + (p.x() - lo.x()) * scale,
                       h - options.margin_px - (p.y() - lo.y()) * scale);
  };
  for (size_t i = 1; i < xy.size(); ++i)
    cv::line(image, pixel(xy[i - 1]), pixel(xy[i]), cv::Scalar(170, 170, 170), 2, cv::LINE_AA);
  for (const auto& a : result.associations) {
    const auto k = prior.IndexOf(a.frame);
    if (k) cv::circle(image, pixel(xy[*k]), 3, ClusterColour(a.cluster), cv::FILLED, cv::LINE_AA);
  }
  const double arrow_m = options.arrow_m > 0 ? options.arrow_m : 0.08 * extent.maxCoeff();
  for (const auto& c : result.clusters) {
    const Eigen::Vector2d from = g.Project(c.centroid);
    Eigen::Vector2d dir = g.Project(c.direction);
    if (dir.norm() < 1e-9) continue;
    dir.normalize();
    const cv::Point2d p0 = pixel(from), p1 = pixel(from + arrow_m * dir);
    cv::arrowedLine(image, p0, p1, cv::Scalar(0, 0, 0), 4, cv::LINE_AA, 0, 0.25);
    cv::arrowedLine(image, p0, p1, ClusterColour(c.id), 2, cv::LINE_AA, 0, 0.25);
    cv::putText(image, std::to_string(c.id), p0 + cv::Point2d(6, -6), cv::FONT_HERSHEY_SIMPLEX, 0.5,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  cv::putText(image,
              std::to_string(result.clusters.size()) + " clusters, " +
                  std::to_string(result.associations.size()) + " associations",
              cv::Point(10, 20), cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  return image;
}

}  // namespace jvl::direction
