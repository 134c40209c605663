#include "vision/orb_features.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "vision/patch_align.h"

namespace jvl::vision {
namespace {

constexpr int kHalfPatch = 15;  // BRIEF patch 31x31 (Rublee et al. 2011).

// Orientation by the intensity centroid of a circular patch (Rosin 1999; ORB Sec. 3.2):
// theta = atan2(m01, m10), m_pq = sum x^p y^q I(x, y).
float IntensityCentroidAngle(const cv::Mat& level, int x, int y) {
  int64_t m01 = 0, m10 = 0;
  for (int dy = -kHalfPatch; dy <= kHalfPatch; ++dy) {
    const int half_width = static_cast<int>(
        std::floor(std::sqrt(static_cast<double>(kHalfPatch * kHalfPatch - dy * dy)) + 1e-9));
    const uint8_t* row = level.ptr<uint8_t>(y + dy);
    for (int dx = -half_width; dx <= half_width; ++dx) {
      const int v = row[x + dx];
      m10 += dx * v;
      m01 += dy * v;
    }
  }
  double angle = std::atan2(static_cast<double>(m01), static_cast<double>(m10)) * 180.0 / M_PI;
  if (angle < 0) angle += 360.0;
  return static_cast<float>(angle >= 360.0 ? 0.0 : angle);
}

// Number of features wanted on each level: a geometric series in 1/scale so that the density
// per unit image area is the same on every level (ORB-SLAM2's ORBextractor).
std::vector<int> FeaturesPerLevel(const OrbOptions& o) {
  const double f = 1.0 / o.scale_factor;
  double per_level = o.num_features * (1 - f) / (1 - std::pow(f, o.num_levels));
  std::vector<int> n(o.num_levels);
  int total = 0;
  for (int l = 0; l + 1 < o.num_levels; ++l) {
    n[l] = static_cast<int>(std::lround(per_level));
    total += n[l];
    per_level *= f;
  }
  n[o.num_levels - 1] = std::max(0, o.num_features - total);
  return n;
}

// FAST corners in one grid cell [x0, x1) x [y0, y1); the ROI is widened by the 3-pixel FAST
// radius so that corners on the whole cell can be found.
std::vector<cv::KeyPoint> DetectInCell(const cv::Mat& level, int x0, int y0, int x1, int y1,
                                       const OrbOptions& o) {
  const cv::Rect roi(x0 - 3, y0 - 3, x1 - x0 + 6, y1 - y0 + 6);
  std::vector<cv::KeyPoint> corners;
  cv::FAST(level(roi), corners, o.fast_threshold, true);
  if (corners.empty()) cv::FAST(level(roi), corners, o.fast_min_threshold, true);
  for (auto& c : corners) c.pt += cv::Point2f(static_cast<float>(roi.x), static_cast<float>(roi.y));
  // Strongest first; ties by position for determinism.
  std::stable_sort(corners.begin(), corners.end(),
                   [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
                     if (a.response != b.response) return a.response > b.response;
                     if (a.pt.y != b.pt.y) return a.pt.y < b.pt.y;
                     return a.pt.x < b.pt.x;
                   });
  return corners;
}

// Detects on one level and keeps `wanted` corners spread over the grid: rank 0 of every cell,
// then rank 1, ...; the last partial rank keeps its strongest corners.
std::vector<cv::KeyPoint> DetectLevel(const cv::Mat& level, int wanted, const OrbOptions& o) {
  const int x_min = o.edge_threshold, y_min = o.edge_threshold;
  const int x_max = level.cols - o.edge_threshold, y_max = level.rows - o.edge_threshold;
  if (wanted <= 0 || x_max - x_min < 8 || y_max - y_min < 8) return {};
  const int nx = std::max(1, (x_max - x_min) / o.cell_size);
  const int ny = std::max(1, (y_max - y_min) / o.cell_size);
  std::vector<std::vector<cv::KeyPoint>> cells;
  size_t max_rank = 0;
  for (int j = 0; j < ny; ++j) {
    const int y0 = y_min + (y_max - y_min) * j / ny, y1 = y_min + (y_max - y_min) * (j + 1) / ny;
    for (int i = 0; i < nx; ++i) {
      const int x0 = x_min + (x_max - x_min) * i / nx, x1 = x_min + (x_max - x_min) * (i + 1) / nx;
      cells.push_back(DetectInCell(level, x0, y0, x1, y1, o));
      max_rank = std::max(max_rank, cells.back().size());
    }
  }
  std::vector<cv::KeyPoint> kept;
  for (size_t rank = 0; rank < max_rank && static_cast<int>(kept.size()) < wanted; ++rank) {
    std::vector<cv::KeyPoint> layer;
    for (const auto& cell : cells) {
      if (rank < cell.size()) layer.push_back(cell[rank]);
    }
    const size_t room = static_cast<size_t>(wanted) - kept.size();
    if (layer.size() > room) {
      std::stable_sort(
          layer.begin(), layer.end(),
          [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.response > b.response; });
      layer.resize(room);
    }
    kept.insert(kept.end(), layer.begin(), layer.end());
  }
  return kept;
}

}  // namespace

void OrbOptions::Check() const {
  JVL_CHECK(num_features > 0, "orb: num_features must be > 0, got " << num_features);
  JVL_CHECK(num_levels >= 1 && num_levels <= 16, "orb: num_levels must be in [1, 16]");
  JVL_CHECK(scale_factor > 1.0 && scale_factor < 2.0, "orb: scale_factor must be in (1, 2)");
  JVL_CHECK(fast_threshold > 0 && fast_min_threshold > 0 && fast_min_threshold <= fast_threshold,
            "orb: need 0 < fast_min_threshold <= fast_threshold");
  JVL_CHECK(cell_size >= 8, "orb: cell_size must be >= 8 pixels, got " << cell_size);
  JVL_CHECK(edge_threshold >= kHalfPatch + 1, "orb: edge_threshold must be >= 16");
}

std::vector<double> LevelScales(const OrbOptions& options) {
  std::vector<double> scales(options.num_levels, 1.0);
  for (int l = 1; l < options.num_levels; ++l) scales[l] = scales[l - 1] * options.scale_factor;
  return scales;
}

OrbFeatures ExtractOrb(const cv::Mat& image, const OrbOptions& options) {
  options.Check();
  JVL_CHECK(!image.empty(), "orb: empty image");
  cv::Mat gray = image;
  if (image.channels() == 3) cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  JVL_CHECK(gray.type() == CV_8UC1, "orb: image must be 8-bit grey or BGR");
  const std::vector<double> scales = LevelScales(options);
  const std::vector<int> wanted = FeaturesPerLevel(options);

  // Same pyramid as cv::ORB builds (each level resized from the previous one), so that the
  // descriptors computed below sample the level the corner was found on.
  std::vector<cv::KeyPoint> all;
  std::vector<cv::Size> sizes;
  OrbFeatures out;
  cv::Mat level = gray;
  for (int l = 0; l < options.num_levels; ++l) {
    if (l > 0) {
      const cv::Size size(cvRound(gray.cols / scales[l]), cvRound(gray.rows / scales[l]));
      cv::Mat next;
      cv::resize(level, next, size, 0, 0, cv::INTER_LINEAR);
      level = next;
    }
    if (options.keep_pyramid) out.pyramid.push_back(level);
    sizes.push_back(level.size());
    for (cv::KeyPoint& kp : DetectLevel(level, wanted[l], options)) {
      kp.angle = IntensityCentroidAngle(level, cvRound(kp.pt.x), cvRound(kp.pt.y));
      kp.octave = l;
      kp.size = static_cast<float>(31 * scales[l]);
      kp.pt *= static_cast<float>(scales[l]);  // As cv::ORB expects.
      all.push_back(kp);
    }
  }

  auto orb = cv::ORB::create(options.num_features, static_cast<float>(options.scale_factor),
                             options.num_levels, options.edge_threshold, 0, 2,
                             cv::ORB::HARRIS_SCORE, 2 * kHalfPatch + 1, options.fast_threshold);
  cv::Mat desc;
  orb->compute(gray, all, desc);  // May drop corners near the border; keeps the rest in order.
  out.keypoints.reserve(all.size());
  out.descriptors.resize(all.size());
  for (size_t i = 0; i < all.size(); ++i) {
    // cv::ORB's convention (level pixel x scale) back to the level pixel, then to level-0
    // coordinates through the resizing.
    const int o = all[i].octave;
    const Eigen::Vector2d level_xy(std::round(all[i].pt.x / scales[o]),
                                   std::round(all[i].pt.y / scales[o]));
    const Eigen::Vector2f uv = LevelToImage(level_xy, sizes[o], gray.size()).cast<float>();
    out.keypoints.push_back({uv, o, all[i].angle, all[i].response});
    std::copy(desc.ptr<uint8_t>(static_cast<int>(i)), desc.ptr<uint8_t>(static_cast<int>(i)) + 32,
              out.descriptors[i].begin());
  }
  return out;
}

}  // namespace jvl::vision
