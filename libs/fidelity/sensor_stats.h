// Sensor statistics of one LiDAR scan and one camera image, computed the same way on real and
// simulated sequences: the sensor side of the simulator's fidelity table (docs/sim.md,
// `sensor_stats`). Every statistic is a property of the raw data (no pose, no other frame).
#pragma once

#include <array>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <vector>

#include "geometry/point_cloud.h"

namespace jvl::fidelity {

// Upper edges of the range bins (m); the last bin is open: [0, 5), [5, 10), ... [80, inf).
inline constexpr std::array<double, 5> kRangeBinEdges = {5, 10, 20, 40, 80};

struct ScanStatsOptions {
  double sensor_height = 1.73;    // Nominal height of the sensor above the road (m).
  double ground_cell = 1.0;       // Side of the xy cells of the ground test (m).
  double ground_tolerance = 0.2;  // A point within this of its cell's lowest point is ground (m),
  double ground_band = 1.0;       // if that lowest point is within this of the nominal road (m).
  double shape_min_range = 3.0;   // Shape classes of the other points within these ranges (m):
  double shape_max_range = 40.0;  // beyond, neighbourhoods are too sparse to tell shapes apart.
  double voxel_size = 0.15;       // Downsampling before the shape classes (m).
  double radius = 0.5;            // Neighbourhood radius of the local shape (m).
  int min_neighbours = 6;         // Fewer neighbours (itself included): "sparse".
  double normal_tolerance_deg = 20;  // Planar with normal within this of horizontal: vertical.
  double far_range = 40.0;           // Returns beyond this horizontal distance count as far (m).
  void Check() const;
};

// Fractions are of all points (ground) or of the non-ground voxels within the shape ranges
// (the shape classes, which sum to 1). NaN where there is nothing to count.
struct ScanStats {
  size_t points = 0;
  int rings = 0;                  // Segments between crossings of the seam behind the sensor.
  double ring_points_median = 0;  // Points per ring: median and 10 % quantile over the rings.
  double ring_points_p10 = 0;
  double range_median = 0;  // Horizontal-and-vertical distance from the sensor (m).
  std::array<double, kRangeBinEdges.size() + 1> range_fraction{};
  double intensity_median = 0;  // NaN without intensities.
  double intensity_p90 = 0;
  double ground_fraction = 0;  // Points on the lowest surface of their xy cell near road level.
  size_t shape_voxels = 0;     // Non-ground voxels classified below.
  double vertical_planar = 0;  // Facades, walls, car sides: planar, normal near horizontal.
  double other_planar = 0;     // Planar, tilted or horizontal (roofs, bonnets, kerbs).
  double linear = 0;           // Poles, trunks, edges, single rings on far surfaces.
  double scattered = 0;        // Volumetric: foliage, clutter.
  double sparse = 0;           // Fewer than min_neighbours neighbours.
  // Of the same voxels: local normal (least principal axis) within 60 degrees of the sensor's x
  // axis, |n_x| >= 0.5. On a road, surfaces that face along it: what constrains a registration
  // along the direction of travel (facades and hedge rows parallel to the road do not).
  double facing_forward = 0;
  // Non-ground returns beyond far_range (horizontal) within 45 degrees of the sensor's +x axis
  // (ahead) and of its -x axis (behind): whether the world goes on along the road. Near zero
  // ahead: the scanner looks into a void (a simulated world that ends) or at a near wall.
  size_t far_ahead = 0;
  size_t far_behind = 0;
};

// Rings: a new ring starts where, in storage order, the azimuth crosses the seam behind the
// sensor (KITTI and sim_sequence store a scan ring by ring, each a sweep from behind to behind).
ScanStats ComputeScanStats(const PointCloud& scan, const ScanStatsOptions& options);

struct ImageStatsOptions {
  int fast_threshold = 20;  // FAST-9 threshold of the corner count (ORB-SLAM2's first threshold).
  int grid_cols = 16;       // Grid of the corner spread.
  int grid_rows = 5;
  int min_corners_per_cell = 3;
  int block_size = 32;      // Blocks of the local contrast (px).
  int orb_features = 2000;  // ExtractOrb's feature budget (vision/orb_features.h).
  void Check() const;
};

struct ImageStats {
  double mean = 0;            // Grey level.
  double contrast = 0;        // Standard deviation of the grey levels over the image.
  double local_contrast = 0;  // Median over block_size blocks of the blocks' standard deviation.
  double gradient_mean = 0;   // Sobel gradient magnitude / 8 (grey levels per pixel).
  double gradient_p90 = 0;
  double dark_fraction = 0;    // Grey level <= 5.
  double bright_fraction = 0;  // Grey level >= 250.
  size_t fast_corners = 0;     // FAST-9 corners (non-maximum suppressed) at fast_threshold.
  double corner_cells = 0;     // Fraction of grid cells with at least min_corners_per_cell.
  size_t orb_keypoints = 0;    // ExtractOrb with orb_features.
  double orb_cells = 0;        // Fraction of grid cells with at least one ORB keypoint.
};

// `image` is 8-bit grey (colour is converted).
ImageStats ComputeImageStats(const cv::Mat& image, const ImageStatsOptions& options);

// The body of a sensor_stats artifact's "scan" / "image" part (schemas/sensor_stats.schema.json):
// for every statistic its median, 10 % and 90 % quantile over the frames where it is finite
// (null if none) and the per-frame values (null where not finite).
nlohmann::json SummariseScans(const std::vector<ScanStats>& stats);
// One statistic's summary of that form from its per-frame values (NaN where a frame has none),
// with the mean of the finite values too when asked (the stages' statistics,
// fidelity/stage_stats.h).
nlohmann::json SummariseValues(const std::vector<double>& values, bool with_mean = false);
nlohmann::json SummariseImages(const std::vector<ImageStats>& stats);

}  // namespace jvl::fidelity
