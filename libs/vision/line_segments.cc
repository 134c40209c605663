#include "vision/line_segments.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/check.h"

#ifdef JVL_HAVE_XIMGPROC
#include <opencv2/ximgproc/fast_line_detector.hpp>
#endif

namespace jvl {

LineDetector ParseLineDetector(const std::string& name) {
  if (name == "lsd") return LineDetector::kLsd;
  if (name == "fld") return LineDetector::kFld;
  JVL_THROW("unknown line detector '" << name << "' (expected lsd or fld)");
}

std::string ToString(LineDetector detector) {
  return detector == LineDetector::kLsd ? "lsd" : "fld";
}

bool FastLineDetectorAvailable() {
#ifdef JVL_HAVE_XIMGPROC
  return true;
#else
  return false;
#endif
}

void LineSegmentOptions::Check() const {
  JVL_CHECK(scale > 0.05 && scale <= 1.0, "scale must be in (0.05, 1], got " << scale);
  JVL_CHECK(min_length_px >= 0, "min_length_px must be >= 0, got " << min_length_px);
  // The fast line detector asserts on zero thresholds, so they must be strictly positive.
  JVL_CHECK(canny_low > 0 && canny_high >= canny_low && std::isfinite(canny_high),
            "Canny thresholds (--canny-low, --canny-high) must satisfy 0 < low <= high, got "
                << canny_low << ", " << canny_high);
  JVL_CHECK(detector != LineDetector::kFld || FastLineDetectorAvailable(),
            "line detector 'fld' needs opencv_ximgproc, which this build lacks; use lsd");
}

namespace {

std::vector<cv::Vec4f> RunDetector(const cv::Mat& grey, const LineSegmentOptions& options,
                                   double min_length_scaled) {
  std::vector<cv::Vec4f> lines;
  if (options.detector == LineDetector::kLsd) {
    // No refinement and no internal rescaling: the caller already resized the image.
    cv::Ptr<cv::LineSegmentDetector> lsd = cv::createLineSegmentDetector(cv::LSD_REFINE_NONE, 1.0);
    lsd->detect(grey, lines);
    return lines;
  }
#ifdef JVL_HAVE_XIMGPROC
  // Merging collinear pieces triples the run time; the VP estimator does not need it.
  const int length_threshold = std::max(2, static_cast<int>(min_length_scaled));
  cv::Ptr<cv::ximgproc::FastLineDetector> fld = cv::ximgproc::createFastLineDetector(
      length_threshold, 1.414213562f, options.canny_low, options.canny_high, 3, false);
  fld->detect(grey, lines);
#endif
  return lines;
}

}  // namespace

std::vector<LineSegment> DetectLineSegments(const cv::Mat& image,
                                            const LineSegmentOptions& options) {
  options.Check();
  std::vector<LineSegment> segments;
  if (image.empty()) return segments;
  JVL_CHECK(image.depth() == CV_8U,
            "line detection needs an 8-bit image, got depth " << image.depth());
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  if (image.channels() == 4) cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  cv::Mat small = grey;
  if (options.scale < 1.0) {
    cv::resize(grey, small, cv::Size(), options.scale, options.scale, cv::INTER_AREA);
  }
  if (small.cols < 4 || small.rows < 4) return segments;
  const std::vector<cv::Vec4f> lines =
      RunDetector(small, options, options.min_length_px * options.scale);
  // Pixel centres: x_full = (x_small + 0.5) / scale - 0.5.
  const double sx = static_cast<double>(grey.cols) / small.cols;
  const double sy = static_cast<double>(grey.rows) / small.rows;
  segments.reserve(lines.size());
  for (const cv::Vec4f& l : lines) {
    LineSegment s;
    s.p0 = {(l[0] + 0.5) * sx - 0.5, (l[1] + 0.5) * sy - 0.5};
    s.p1 = {(l[2] + 0.5) * sx - 0.5, (l[3] + 0.5) * sy - 0.5};
    if (s.p0.allFinite() && s.p1.allFinite() && s.length() >= options.min_length_px) {
      segments.push_back(s);
    }
  }
  return segments;
}

}  // namespace jvl
