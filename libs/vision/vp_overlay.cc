#include "vision/vp_overlay.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

namespace jvl {
namespace {

cv::Scalar VpColour(int index) {
  switch (index) {
    case 0:
      return {0, 0, 255};  // Red.
    case 1:
      return {0, 200, 0};  // Green.
    case 2:
      return {255, 80, 0};  // Blue.
    case -1:
      return {150, 150, 150};
    default:
      return {255, 0, 255};
  }
}

cv::Point ToPoint(const Eigen::Vector2d& p) {
  return {static_cast<int>(std::lround(p.x())), static_cast<int>(std::lround(p.y()))};
}

// Arrow from the image centre towards the VP, clipped at the border (for VPs outside the image
// or at infinity, where the marker itself cannot be drawn).
void DrawBorderArrow(cv::Mat& out, const Eigen::Vector3d& d, const PinholeCamera& camera,
                     const cv::Scalar& colour) {
  const Eigen::Vector2d centre(camera.cx, camera.cy);
  Eigen::Vector2d dir(camera.fx * d.x(), camera.fy * d.y());  // Image direction to the VP.
  const Eigen::Vector2d vp = camera.Project(d.z() > 1e-9 ? d : Eigen::Vector3d(0, 0, 1));
  if (d.z() > 1e-9) dir = vp - centre;
  if (dir.norm() < 1e-9) return;
  dir.normalize();
  const double margin = 12;
  double t = 1e18;
  if (dir.x() > 1e-12) t = std::min(t, (out.cols - margin - centre.x()) / dir.x());
  if (dir.x() < -1e-12) t = std::min(t, (margin - centre.x()) / dir.x());
  if (dir.y() > 1e-12) t = std::min(t, (out.rows - margin - centre.y()) / dir.y());
  if (dir.y() < -1e-12) t = std::min(t, (margin - centre.y()) / dir.y());
  const Eigen::Vector2d tip = centre + t * dir;
  cv::arrowedLine(out, ToPoint(tip - 40 * dir), ToPoint(tip), colour, 3, cv::LINE_AA, 0, 0.4);
}

}  // namespace

cv::Mat DrawVpOverlay(const cv::Mat& image, const PinholeCamera& camera, const VpResult& result) {
  cv::Mat out;
  if (image.channels() == 1) {
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  } else {
    out = image.clone();
  }
  for (size_t i = 0; i < result.segments.size(); ++i) {
    const int vp = i < result.segment_vp.size() ? result.segment_vp[i] : -1;
    cv::line(out, ToPoint(result.segments[i].p0), ToPoint(result.segments[i].p1), VpColour(vp),
             vp < 0 ? 1 : 2, cv::LINE_AA);
  }
  for (size_t k = 0; k < result.vps.size(); ++k) {
    const VanishingPoint& vp = result.vps[k];
    const cv::Scalar colour = VpColour(static_cast<int>(k));
    const bool inside = vp.uv.allFinite() && camera.InImage(vp.uv);
    if (inside) {
      const int radius = vp.is_forward ? 12 : 8;
      cv::circle(out, ToPoint(vp.uv), radius, colour, 2, cv::LINE_AA);
      cv::drawMarker(out, ToPoint(vp.uv), colour, cv::MARKER_CROSS, 2 * radius, 1, cv::LINE_AA);
    } else {
      DrawBorderArrow(out, vp.direction, camera, colour);
    }
    const std::string label = "VP" + std::to_string(k) + (vp.is_forward ? " fwd" : "") +
                              " n=" + std::to_string(vp.inliers);
    cv::putText(out, label, cv::Point(10, 20 + 20 * static_cast<int>(k)), cv::FONT_HERSHEY_SIMPLEX,
                0.6, colour, 2, cv::LINE_AA);
  }
  return out;
}

}  // namespace jvl
