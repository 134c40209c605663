#include "fidelity/sensor_stats.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/check.h"
#include "core/statistics.h"
#include "lidar/voxel_grid.h"
#include "vision/orb_features.h"

namespace jvl::fidelity {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// Sizes of the rings in storage order. KITTI and sim_sequence store a scan ring by ring, each a
// sweep from behind to behind (a scan that starts mid-sweep has its first ring split between
// the first and the last segment). A ring ends where the azimuth crosses the seam behind the
// sensor (a step of more than half a turn between consecutive points) or steps back against
// the sweep by more than kRestart, 20 degrees (the next ring starting while this one ended early,
// e.g. an upward beam that saw nothing behind); smaller backward steps are the jitter of near
// returns (up to 11 degrees at 4 m on KITTI).
std::vector<size_t> RingSizes(const std::vector<Eigen::Vector3d>& points) {
  constexpr double kRestart = 20.0 * M_PI / 180.0;
  std::vector<size_t> sizes;
  if (points.empty()) return sizes;
  std::vector<double> azimuth(points.size()), steps;
  for (size_t i = 0; i < points.size(); ++i) azimuth[i] = std::atan2(points[i].y(), points[i].x());
  for (size_t i = 1; i < points.size(); ++i) steps.push_back(azimuth[i] - azimuth[i - 1]);
  const double direction = steps.empty() || Median(steps) >= 0 ? 1.0 : -1.0;
  size_t size = 1;
  for (size_t i = 1; i < points.size(); ++i) {
    const double step = azimuth[i] - azimuth[i - 1];
    if (std::abs(step) > M_PI || direction * step < -kRestart) {
      sizes.push_back(size);
      size = 0;
    }
    ++size;
  }
  sizes.push_back(size);
  return sizes;
}

// Ground test: in xy cells of ground_cell, a point is ground when it is within
// ground_tolerance of its cell's lowest point and that lowest point is within ground_band of
// the nominal road height.
std::vector<char> GroundMask(const std::vector<Eigen::Vector3d>& points,
                             const ScanStatsOptions& o) {
  std::unordered_map<uint64_t, double> lowest;
  lowest.reserve(points.size() / 4);
  const double inv = 1.0 / o.ground_cell;
  auto key = [&](const Eigen::Vector3d& p) {
    return lidar::PackCell(static_cast<int64_t>(std::floor(p.x() * inv)),
                           static_cast<int64_t>(std::floor(p.y() * inv)), 0);
  };
  for (const auto& p : points) {
    auto [it, inserted] = lowest.emplace(key(p), p.z());
    if (!inserted) it->second = std::min(it->second, p.z());
  }
  std::vector<char> ground(points.size(), 0);
  for (size_t i = 0; i < points.size(); ++i) {
    const double low = lowest.at(key(points[i]));
    ground[i] = std::abs(low + o.sensor_height) <= o.ground_band &&
                points[i].z() - low <= o.ground_tolerance;
  }
  return ground;
}

// name -> per-frame values, in a fixed order of names.
using Series = std::vector<std::pair<std::string, std::vector<double>>>;

// Appends the series `name`: get(x) for every x of stats.
template <typename Stats, typename Get>
void AddSeries(const std::vector<Stats>& stats, const std::string& name, Get get, Series* out) {
  std::vector<double> values;
  values.reserve(stats.size());
  for (const Stats& x : stats) values.push_back(static_cast<double>(get(x)));
  out->emplace_back(name, std::move(values));
}

Series ScanSeries(const std::vector<ScanStats>& s) {
  Series out;
  auto add = [&](const std::string& name, auto get) { AddSeries(s, name, get, &out); };
  add("points", [](const ScanStats& x) { return x.points; });
  add("rings", [](const ScanStats& x) { return x.rings; });
  add("ring_points_median", [](const ScanStats& x) { return x.ring_points_median; });
  add("ring_points_p10", [](const ScanStats& x) { return x.ring_points_p10; });
  add("range_median_m", [](const ScanStats& x) { return x.range_median; });
  const char* bins[] = {"range_0_5",   "range_5_10",  "range_10_20",
                        "range_20_40", "range_40_80", "range_80_up"};
  for (size_t b = 0; b < 6; ++b)
    add(bins[b], [b](const ScanStats& x) { return x.range_fraction[b]; });
  add("intensity_median", [](const ScanStats& x) { return x.intensity_median; });
  add("intensity_p90", [](const ScanStats& x) { return x.intensity_p90; });
  add("ground", [](const ScanStats& x) { return x.ground_fraction; });
  add("shape_voxels", [](const ScanStats& x) { return x.shape_voxels; });
  add("vertical_planar", [](const ScanStats& x) { return x.vertical_planar; });
  add("other_planar", [](const ScanStats& x) { return x.other_planar; });
  add("linear", [](const ScanStats& x) { return x.linear; });
  add("scattered", [](const ScanStats& x) { return x.scattered; });
  add("sparse", [](const ScanStats& x) { return x.sparse; });
  add("facing_forward", [](const ScanStats& x) { return x.facing_forward; });
  add("far_ahead", [](const ScanStats& x) { return x.far_ahead; });
  add("far_behind", [](const ScanStats& x) { return x.far_behind; });
  return out;
}

Series ImageSeries(const std::vector<ImageStats>& s) {
  Series out;
  auto add = [&](const std::string& name, auto get) { AddSeries(s, name, get, &out); };
  add("mean", [](const ImageStats& x) { return x.mean; });
  add("contrast", [](const ImageStats& x) { return x.contrast; });
  add("local_contrast", [](const ImageStats& x) { return x.local_contrast; });
  add("gradient_mean", [](const ImageStats& x) { return x.gradient_mean; });
  add("gradient_p90", [](const ImageStats& x) { return x.gradient_p90; });
  add("dark_fraction", [](const ImageStats& x) { return x.dark_fraction; });
  add("bright_fraction", [](const ImageStats& x) { return x.bright_fraction; });
  add("fast_corners", [](const ImageStats& x) { return x.fast_corners; });
  add("corner_cells", [](const ImageStats& x) { return x.corner_cells; });
  add("orb_keypoints", [](const ImageStats& x) { return x.orb_keypoints; });
  add("orb_cells", [](const ImageStats& x) { return x.orb_cells; });
  return out;
}

nlohmann::json Finite(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// {"name": SummariseValues(values)}.
nlohmann::json Summarise(const Series& series) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [name, values] : series) out[name] = SummariseValues(values);
  return out;
}

}  // namespace

void ScanStatsOptions::Check() const {
  JVL_CHECK(sensor_height > 0 && ground_cell > 0 && ground_tolerance > 0 && ground_band > 0,
            "scan stats: sensor_height, ground_cell, ground_tolerance and ground_band must be > 0");
  JVL_CHECK(shape_min_range >= 0 && shape_max_range > shape_min_range,
            "scan stats: need 0 <= shape_min_range < shape_max_range");
  JVL_CHECK(voxel_size > 0 && radius > 0, "scan stats: voxel_size and radius must be > 0");
  JVL_CHECK(min_neighbours >= 3, "scan stats: min_neighbours must be >= 3, got " << min_neighbours);
  JVL_CHECK(normal_tolerance_deg > 0 && normal_tolerance_deg < 45,
            "scan stats: normal_tolerance_deg must be in (0, 45)");
  JVL_CHECK(far_range > 0, "scan stats: far_range must be > 0, got " << far_range);
}

ScanStats ComputeScanStats(const PointCloud& scan, const ScanStatsOptions& o) {
  o.Check();
  ScanStats s;
  const auto& pts = scan.points;
  s.points = pts.size();
  if (pts.empty()) {
    s.ring_points_median = s.ring_points_p10 = s.range_median = kNan;
    s.range_fraction.fill(kNan);
    s.intensity_median = s.intensity_p90 = s.ground_fraction = kNan;
    s.vertical_planar = s.other_planar = s.linear = s.scattered = s.sparse = kNan;
    s.facing_forward = kNan;
    return s;
  }

  const std::vector<size_t> rings = RingSizes(pts);
  s.rings = static_cast<int>(rings.size());
  std::vector<double> ring_sizes(rings.begin(), rings.end());
  s.ring_points_median = Median(ring_sizes);
  s.ring_points_p10 = Quantile(ring_sizes, 0.1);

  std::vector<double> ranges(pts.size());
  s.range_fraction.fill(0.0);
  for (size_t i = 0; i < pts.size(); ++i) {
    ranges[i] = pts[i].norm();
    const size_t bin = static_cast<size_t>(
        std::upper_bound(kRangeBinEdges.begin(), kRangeBinEdges.end(), ranges[i]) -
        kRangeBinEdges.begin());
    s.range_fraction[bin] += 1.0;
  }
  for (double& f : s.range_fraction) f /= static_cast<double>(pts.size());
  s.range_median = Median(ranges);

  if (scan.intensity.size() == pts.size()) {
    std::vector<double> intensity(scan.intensity.begin(), scan.intensity.end());
    s.intensity_median = Median(intensity);
    s.intensity_p90 = Quantile(intensity, 0.9);
  } else {
    s.intensity_median = s.intensity_p90 = kNan;
  }

  const std::vector<char> ground = GroundMask(pts, o);
  s.ground_fraction = static_cast<double>(std::count(ground.begin(), ground.end(), 1)) / pts.size();

  for (size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector3d& p = pts[i];
    if (ground[i] || p.head<2>().squaredNorm() <= o.far_range * o.far_range) continue;
    if (std::abs(p.y()) < std::abs(p.x())) ++(p.x() > 0 ? s.far_ahead : s.far_behind);
  }

  // Shape classes of the non-ground points within the shape ranges, one per voxel.
  std::vector<Eigen::Vector3d> others;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!ground[i] && ranges[i] >= o.shape_min_range && ranges[i] <= o.shape_max_range)
      others.push_back(pts[i]);
  }
  std::vector<Eigen::Vector3d> voxels;
  for (size_t i : lidar::VoxelDownsample(others, o.voxel_size)) voxels.push_back(others[i]);
  s.shape_voxels = voxels.size();
  if (voxels.empty()) {
    s.vertical_planar = s.other_planar = s.linear = s.scattered = s.sparse = kNan;
    s.facing_forward = kNan;
    return s;
  }
  const lidar::PointGrid grid(voxels, o.radius);
  const double sin_tol = std::sin(o.normal_tolerance_deg * M_PI / 180.0);
  std::array<size_t, 5> counts{};  // vertical planar, other planar, linear, scattered, sparse
  size_t forward = 0;
  std::vector<std::pair<double, int>> near;
  for (const auto& q : voxels) {
    grid.RadiusSearch(q, o.radius, 0, &near);
    if (static_cast<int>(near.size()) < o.min_neighbours) {
      ++counts[4];
      continue;
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& [d2, j] : near) mean += voxels[j];
    mean /= static_cast<double>(near.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& [d2, j] : near) {
      const Eigen::Vector3d d = voxels[j] - mean;
      cov += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    if (std::abs(eig.eigenvectors().col(0).x()) >= 0.5) ++forward;
    // Dimensionality features (Demantke et al. 2011) from the standard deviations along the
    // principal axes, largest first: linear, planar or scattered, whichever is largest.
    const Eigen::Vector3d l = eig.eigenvalues().cwiseMax(0.0);  // Ascending.
    const double s1 = std::sqrt(l(2)), s2 = std::sqrt(l(1)), s3 = std::sqrt(l(0));
    if (s1 <= 0) {
      ++counts[4];
      continue;
    }
    const double a1 = (s1 - s2) / s1, a2 = (s2 - s3) / s1, a3 = s3 / s1;
    if (a1 >= a2 && a1 >= a3) {
      ++counts[2];
    } else if (a3 > a2) {
      ++counts[3];
    } else {
      const Eigen::Vector3d normal = eig.eigenvectors().col(0);
      ++counts[std::abs(normal.z()) <= sin_tol ? 0 : 1];
    }
  }
  const double n = static_cast<double>(voxels.size());
  s.vertical_planar = counts[0] / n;
  s.other_planar = counts[1] / n;
  s.linear = counts[2] / n;
  s.scattered = counts[3] / n;
  s.sparse = counts[4] / n;
  s.facing_forward = forward / n;
  return s;
}

void ImageStatsOptions::Check() const {
  JVL_CHECK(fast_threshold > 0 && fast_threshold < 256,
            "image stats: fast_threshold must be in [1, 255]");
  JVL_CHECK(grid_cols >= 1 && grid_rows >= 1 && min_corners_per_cell >= 1,
            "image stats: grid_cols, grid_rows and min_corners_per_cell must be >= 1");
  JVL_CHECK(block_size >= 4, "image stats: block_size must be >= 4 pixels");
  JVL_CHECK(orb_features > 0, "image stats: orb_features must be > 0");
}

ImageStats ComputeImageStats(const cv::Mat& image, const ImageStatsOptions& o) {
  o.Check();
  JVL_CHECK(!image.empty(), "image stats: empty image");
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image;
  }
  JVL_CHECK(grey.type() == CV_8UC1, "image stats: expected an 8-bit image");
  ImageStats s;
  cv::Scalar mean, stddev;
  cv::meanStdDev(grey, mean, stddev);
  s.mean = mean[0];
  s.contrast = stddev[0];
  const double pixels = static_cast<double>(grey.total());
  s.dark_fraction = cv::countNonZero(grey <= 5) / pixels;
  s.bright_fraction = cv::countNonZero(grey >= 250) / pixels;

  std::vector<double> block_contrast;
  for (int y = 0; y + o.block_size <= grey.rows; y += o.block_size) {
    for (int x = 0; x + o.block_size <= grey.cols; x += o.block_size) {
      cv::meanStdDev(grey(cv::Rect(x, y, o.block_size, o.block_size)), mean, stddev);
      block_contrast.push_back(stddev[0]);
    }
  }
  s.local_contrast = Median(block_contrast);

  cv::Mat gx, gy, magnitude;
  cv::Sobel(grey, gx, CV_32F, 1, 0, 3);
  cv::Sobel(grey, gy, CV_32F, 0, 1, 3);
  cv::magnitude(gx, gy, magnitude);
  magnitude /= 8.0f;
  s.gradient_mean = cv::mean(magnitude)[0];
  std::vector<double> sample;  // Every 4th pixel of every 4th row: enough for a quantile.
  for (int y = 0; y < magnitude.rows; y += 4)
    for (int x = 0; x < magnitude.cols; x += 4) sample.push_back(magnitude.at<float>(y, x));
  s.gradient_p90 = Quantile(sample, 0.9);

  auto cell_of = [&](double u, double v) {
    const int cx = std::clamp(static_cast<int>(u * o.grid_cols / grey.cols), 0, o.grid_cols - 1);
    const int cy = std::clamp(static_cast<int>(v * o.grid_rows / grey.rows), 0, o.grid_rows - 1);
    return cy * o.grid_cols + cx;
  };
  const double cells = static_cast<double>(o.grid_cols * o.grid_rows);
  std::vector<cv::KeyPoint> corners;
  cv::FAST(grey, corners, o.fast_threshold, true, cv::FastFeatureDetector::TYPE_9_16);
  s.fast_corners = corners.size();
  std::vector<int> per_cell(o.grid_cols * o.grid_rows, 0);
  for (const auto& k : corners) ++per_cell[cell_of(k.pt.x, k.pt.y)];
  s.corner_cells = std::count_if(per_cell.begin(), per_cell.end(),
                                 [&](int c) { return c >= o.min_corners_per_cell; }) /
                   cells;

  vision::OrbOptions orb;
  orb.num_features = o.orb_features;
  const vision::OrbFeatures features = vision::ExtractOrb(grey, orb);
  s.orb_keypoints = features.size();
  std::fill(per_cell.begin(), per_cell.end(), 0);
  for (const auto& k : features.keypoints) ++per_cell[cell_of(k.uv.x(), k.uv.y())];
  s.orb_cells =
      std::count_if(per_cell.begin(), per_cell.end(), [](int c) { return c > 0; }) / cells;
  return s;
}

nlohmann::json SummariseValues(const std::vector<double>& values, bool with_mean) {
  std::vector<double> finite;
  nlohmann::json per_frame = nlohmann::json::array();
  for (double v : values) {
    per_frame.push_back(Finite(v));
    if (std::isfinite(v)) finite.push_back(v);
  }
  nlohmann::json out = {{"median", Finite(Median(finite))},
                        {"p10", Finite(Quantile(finite, 0.1))},
                        {"p90", Finite(Quantile(finite, 0.9))},
                        {"frames", per_frame}};
  if (with_mean) {
    double sum = 0;
    for (const double v : finite) sum += v;
    out["mean"] =
        finite.empty() ? nlohmann::json() : Finite(sum / static_cast<double>(finite.size()));
  }
  return out;
}

nlohmann::json SummariseScans(const std::vector<ScanStats>& stats) {
  return Summarise(ScanSeries(stats));
}

nlohmann::json SummariseImages(const std::vector<ImageStats>& stats) {
  return Summarise(ImageSeries(stats));
}

}  // namespace jvl::fidelity
