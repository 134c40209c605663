#include "lidar/preprocess.h"

#include <pcl/ModelCoefficients.h>
#include <pcl/console/print.h>
#include <pcl/filters/radius_outlier_removal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/check.h"
#include "core/threads.h"
#include "lidar/voxel_grid.h"

namespace jvl::lidar {
namespace {

constexpr double kPi = 3.14159265358979323846;

// PCL prints its own diagnostics (e.g. "[pcl::SampleConsensusModelPlane::isSampleGood] ...")
// to the terminal; the results it returns are checked here, so its text is kept out.
void QuietPcl() {
  static const bool quiet = [] {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
    return true;
  }();
  (void)quiet;
}

pcl::PointCloud<pcl::PointXYZ>::Ptr ToPcl(const std::vector<Eigen::Vector3d>& points) {
  QuietPcl();
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    (*cloud)[i].getVector3fMap() = points[i].cast<float>();
  }
  return cloud;
}

// Union-find over occupied cells for the small-object clustering.
int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

template <typename T>
void Select(const std::vector<uint8_t>& keep, std::vector<T>* v) {
  size_t out = 0;
  for (size_t i = 0; i < v->size(); ++i) {
    if (keep[i]) (*v)[out++] = (*v)[i];
  }
  v->resize(out);
}

}  // namespace

void PreprocessOptions::Check() const {
  JVL_CHECK(min_range >= 0, "min_range must be >= 0, got " << min_range);
  JVL_CHECK(max_range == 0 || max_range > min_range,
            "max_range must be 0 or > min_range, got " << max_range);
  JVL_CHECK(
      std::abs(vertical_correction_deg) < 5,
      "vertical_correction_deg must be a small angle in degrees, got " << vertical_correction_deg);
  JVL_CHECK(voxel_size >= 0, "voxel_size must be >= 0, got " << voxel_size);
  JVL_CHECK(outlier_radius >= 0, "outlier_radius must be >= 0, got " << outlier_radius);
  JVL_CHECK(outlier_method == "grid" || outlier_method == "pcl",
            "outlier_method must be grid or pcl, got '" << outlier_method << "'");
  JVL_CHECK(outlier_min_neighbors >= 0,
            "outlier_min_neighbors must be >= 0, got " << outlier_min_neighbors);
  JVL_CHECK(ground_distance > 0, "ground_distance must be > 0, got " << ground_distance);
  JVL_CHECK(ground_max_angle_deg > 0 && ground_max_angle_deg < 90,
            "ground_max_angle_deg must be in (0, 90) degrees, got " << ground_max_angle_deg);
  JVL_CHECK(ground_max_iterations > 0,
            "ground_max_iterations must be > 0, got " << ground_max_iterations);
  JVL_CHECK(ground_max_samples >= 3, "ground_max_samples must be >= 3, got " << ground_max_samples);
  JVL_CHECK(cluster_cell > 0, "cluster_cell must be > 0, got " << cluster_cell);
  JVL_CHECK(small_object_horizontal >= 0 && small_object_height >= 0,
            "small_object_horizontal and small_object_height must be >= 0");
}

void CorrectVerticalAngle(double angle_rad, std::vector<Eigen::Vector3d>* velo_points) {
  if (angle_rad == 0) return;
  // The rotation by angle_rad about the horizontal axis p x up (Rodrigues' formula with that
  // axis orthogonal to p), written out: the horizontal part is scaled and the height raised, so
  // each point costs one square root instead of an axis-angle matrix.
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  for (Eigen::Vector3d& p : *velo_points) {
    const double horizontal = std::sqrt(p.x() * p.x() + p.y() * p.y());
    if (horizontal < 1e-9) continue;
    const double scale = c - s * p.z() / horizontal;
    p = Eigen::Vector3d(p.x() * scale, p.y() * scale, c * p.z() + s * horizontal);
  }
}

void DeskewScan(const Rigid3d& prev_from_cur, PreprocessedScan* scan) {
  const Vector6d xi = LogSE3(prev_from_cur);
  for (size_t i = 0; i < scan->points.size(); ++i) {
    const double fraction = static_cast<double>(scan->time_fraction[i]);
    const double s = scan->time_offset == 0 ? fraction : fraction + scan->time_offset;
    scan->points[i] = ExpSE3(s * xi) * scan->points[i];
  }
}

float AzimuthTimeFraction(const Eigen::Vector3d& velo_point) {
  return static_cast<float>(-std::atan2(velo_point.y(), velo_point.x()) / (2 * kPi));
}

std::vector<uint8_t> RadiusOutlierMask(const std::vector<Eigen::Vector3d>& points, double radius,
                                       int min_neighbors, const std::string& method, int threads) {
  std::vector<uint8_t> keep(points.size(), 1);
  if (points.empty() || radius <= 0 || min_neighbors <= 0) return keep;
  if (method == "grid") {
    const PointGrid grid(points, radius);
    // A point counts itself: it is kept with min_neighbors others within the radius. Counting
    // stops there, mostly within the point's own cell (the nearer cells are searched first).
    const int needed = min_neighbors + 1;
    constexpr int64_t kChunk = 1024;
    const int64_t n = static_cast<int64_t>(points.size());
    ParallelFor((n + kChunk - 1) / kChunk, threads, [&](int64_t chunk) {
      for (int64_t i = chunk * kChunk; i < std::min(n, (chunk + 1) * kChunk); ++i) {
        keep[i] = grid.CountWithin(points[i], radius, needed) >= needed;
      }
    });
    return keep;
  }
  JVL_CHECK(method == "pcl", "outlier_method must be grid or pcl, got '" << method << "'");
  pcl::RadiusOutlierRemoval<pcl::PointXYZ> filter;
  filter.setInputCloud(ToPcl(points));
  filter.setRadiusSearch(radius);
  filter.setMinNeighborsInRadius(min_neighbors);
  pcl::Indices inliers;
  filter.filter(inliers);
  std::fill(keep.begin(), keep.end(), 0);
  for (const auto i : inliers) keep[static_cast<size_t>(i)] = 1;
  return keep;
}

std::vector<uint8_t> SegmentGround(const std::vector<Eigen::Vector3d>& points,
                                   const PreprocessOptions& options, Eigen::Vector4d* plane,
                                   bool* found) {
  std::vector<uint8_t> ground(points.size(), 0);
  *found = false;
  if (points.size() < 3) return ground;
  // RANSAC on an evenly strided subset (deterministic), then every point is labelled by its
  // distance to the fitted plane.
  const size_t stride =
      std::max<size_t>(1, points.size() / static_cast<size_t>(options.ground_max_samples));
  std::vector<Eigen::Vector3d> subset;
  for (size_t i = 0; i < points.size(); i += stride) subset.push_back(points[i]);
  pcl::SACSegmentation<pcl::PointXYZ> seg;
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_PERPENDICULAR_PLANE);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setAxis(Eigen::Vector3f::UnitY());  // cam0 y is the vertical.
  seg.setEpsAngle(options.ground_max_angle_deg * kPi / 180.0);
  seg.setDistanceThreshold(options.ground_distance);
  seg.setMaxIterations(options.ground_max_iterations);
  seg.setInputCloud(ToPcl(subset));
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  seg.segment(inliers, coefficients);
  if (inliers.indices.size() < 3 || coefficients.values.size() != 4) return ground;
  Eigen::Vector4d p(coefficients.values[0], coefficients.values[1], coefficients.values[2],
                    coefficients.values[3]);
  const double n = p.head<3>().norm();
  if (!(n > 0)) return ground;
  p /= n;
  *plane = p;
  *found = true;
  for (size_t i = 0; i < points.size(); ++i) {
    ground[i] = std::abs(p.head<3>().dot(points[i]) + p[3]) <= options.ground_distance;
  }
  return ground;
}

std::vector<uint8_t> SmallObjectMask(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<uint8_t>& is_ground,
                                     const PreprocessOptions& options, int64_t* clusters_removed) {
  std::vector<uint8_t> keep(points.size(), 1);
  *clusters_removed = 0;
  // Cells of non-ground points, numbered in first-seen order (deterministic).
  const double inv = 1.0 / options.cluster_cell;
  CellMap cell_id(points.size() / 4);
  std::vector<Eigen::Vector3i> cells;
  std::vector<int> point_cell(points.size(), -1);
  uint64_t previous_key = 0;  // Consecutive points often share a cell: no lookup then.
  int previous_id = -1;
  for (size_t i = 0; i < points.size(); ++i) {
    if (is_ground[i]) continue;
    const Eigen::Vector3i c = CellOf(points[i], inv);
    const uint64_t key = PackCell(c.x(), c.y(), c.z());
    if (previous_id >= 0 && key == previous_key) {
      point_cell[i] = previous_id;
      continue;
    }
    const int id = cell_id.Insert(key, static_cast<int>(cells.size()));
    if (id == static_cast<int>(cells.size())) cells.push_back(c);
    point_cell[i] = id;
    previous_key = key;
    previous_id = id;
  }
  // Connected components over the 26-neighbourhood of occupied cells.
  std::vector<int> parent(cells.size());
  std::iota(parent.begin(), parent.end(), 0);
  // Adjacency is symmetric: only the 13 neighbours after the cell in (x, y, z) order are looked
  // up.
  for (size_t a = 0; a < cells.size(); ++a) {
    for (int dx = 0; dx <= 1; ++dx) {
      for (int dy = (dx == 0 ? 0 : -1); dy <= 1; ++dy) {
        for (int dz = (dx == 0 && dy == 0 ? 1 : -1); dz <= 1; ++dz) {
          const Eigen::Vector3i& c = cells[a];
          const int b = cell_id.Find(PackCell(c.x() + dx, c.y() + dy, c.z() + dz));
          if (b < 0) continue;
          const int ra = Find(parent, static_cast<int>(a)), rb = Find(parent, b);
          if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
        }
      }
    }
  }
  // Bounding box of every component.
  std::vector<int> root(cells.size());
  for (size_t a = 0; a < cells.size(); ++a) root[a] = Find(parent, static_cast<int>(a));
  std::vector<Eigen::Vector3d> lo(cells.size(), Eigen::Vector3d::Constant(1e300));
  std::vector<Eigen::Vector3d> hi(cells.size(), Eigen::Vector3d::Constant(-1e300));
  for (size_t i = 0; i < points.size(); ++i) {
    if (point_cell[i] < 0) continue;
    const int r = root[point_cell[i]];
    lo[r] = lo[r].cwiseMin(points[i]);
    hi[r] = hi[r].cwiseMax(points[i]);
  }
  std::vector<uint8_t> small(cells.size(), 0);
  for (size_t r = 0; r < cells.size(); ++r) {
    if (root[r] != static_cast<int>(r)) continue;
    const Eigen::Vector3d e = hi[r] - lo[r];
    small[r] = e.x() < options.small_object_horizontal && e.z() < options.small_object_horizontal &&
               e.y() < options.small_object_height;
    *clusters_removed += small[r];
  }
  for (size_t i = 0; i < points.size(); ++i) {
    if (point_cell[i] >= 0 && small[root[point_cell[i]]]) keep[i] = 0;
  }
  return keep;
}

PreprocessedScan PreprocessScan(const PointCloud& velo_scan, const Rigid3d& cam0_from_velo,
                                const PreprocessOptions& options, int threads) {
  PreprocessedScan out;
  PreprocessCounts& counts = out.counts;
  counts.input = static_cast<int64_t>(velo_scan.size());
  // Range cut (supplement 1.1) in the sensor frame, dropping non-finite points on the way.
  std::vector<Eigen::Vector3d> velo;
  velo.reserve(velo_scan.size());
  const double min2 = options.min_range * options.min_range;
  const double max2 = options.max_range * options.max_range;
  for (const Eigen::Vector3d& p : velo_scan.points) {
    if (!p.allFinite()) {
      ++counts.non_finite;
      continue;
    }
    const double r2 = p.squaredNorm();
    if (r2 < min2 || (options.max_range > 0 && r2 > max2)) continue;
    velo.push_back(p);
  }
  counts.after_range = static_cast<int64_t>(velo.size());
  CorrectVerticalAngle(options.vertical_correction_deg * kPi / 180.0, &velo);
  // Downsampling first keeps the PCL filters and everything after them within budget.
  const std::vector<size_t> kept = VoxelDownsample(velo, options.voxel_size);
  out.points.reserve(kept.size());
  out.time_fraction.reserve(kept.size());
  for (const size_t i : kept) {
    out.points.push_back(cam0_from_velo * velo[i]);
    out.time_fraction.push_back(AzimuthTimeFraction(velo[i]));
  }
  counts.after_voxel = static_cast<int64_t>(out.points.size());

  const std::vector<uint8_t> inlier =
      RadiusOutlierMask(out.points, options.outlier_radius, options.outlier_min_neighbors,
                        options.outlier_method, threads);
  Select(inlier, &out.points);
  Select(inlier, &out.time_fraction);
  counts.after_outliers = static_cast<int64_t>(out.points.size());

  out.is_ground = SegmentGround(out.points, options, &out.ground_plane, &out.ground_found);
  if (options.remove_small_objects) {
    const std::vector<uint8_t> keep =
        SmallObjectMask(out.points, out.is_ground, options, &counts.small_object_clusters);
    counts.small_object_points =
        static_cast<int64_t>(std::count(keep.begin(), keep.end(), uint8_t{0}));
    Select(keep, &out.points);
    Select(keep, &out.time_fraction);
    Select(keep, &out.is_ground);
  }
  counts.ground = static_cast<int64_t>(std::count(out.is_ground.begin(), out.is_ground.end(), 1));
  counts.output = static_cast<int64_t>(out.points.size());
  return out;
}

}  // namespace jvl::lidar
