// Line segments of a greyscale image, the input of vanishing point detection (Supplement 1.4,
// step 1). Two detectors are available: OpenCV's LSD (imgproc) and the Fast Line Detector of
// opencv_contrib's ximgproc; docs/vp_detect.md compares them on KITTI.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace jvl {

struct LineSegment {
  Eigen::Vector2d p0 = Eigen::Vector2d::Zero();  // Endpoints in full-resolution pixels.
  Eigen::Vector2d p1 = Eigen::Vector2d::Zero();
  double length() const { return (p1 - p0).norm(); }
};

enum class LineDetector { kLsd, kFld };
LineDetector ParseLineDetector(const std::string& name);  // "lsd" | "fld"
std::string ToString(LineDetector detector);
// False when the binary was built without opencv_ximgproc (then only LSD is available).
bool FastLineDetectorAvailable();

struct LineSegmentOptions {
  // FLD when the build has opencv_ximgproc (faster, see docs/vp_detect.md), else LSD.
  LineDetector detector = FastLineDetectorAvailable() ? LineDetector::kFld : LineDetector::kLsd;
  // The image is resized by this factor (area interpolation) before detection; endpoints are
  // mapped back to full resolution. 0.5 halves the time of FLD at some accuracy cost on KITTI
  // (p90 forward error 0.57 instead of 0.20 deg, docs/vp_detect.md).
  double scale = 1.0;
  // Segments shorter than this (full-resolution pixels) are dropped: short segments carry
  // little orientation information and are mostly texture (foliage, gravel).
  double min_length_px = 25.0;
  // FLD only: Canny thresholds of the edge map the segments are fitted to.
  double canny_low = 50.0;
  double canny_high = 50.0;
  void Check() const;
};

// Detects segments in an 8-bit image (colour images are converted to grey). An empty or
// featureless image gives an empty list. Deterministic; uses the calling thread only.
std::vector<LineSegment> DetectLineSegments(const cv::Mat& image,
                                            const LineSegmentOptions& options);

}  // namespace jvl
