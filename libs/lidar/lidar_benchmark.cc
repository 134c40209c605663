// Micro-benchmarks of the neighbour search behind normals and outlier removal: the hashed
// grid (PointGrid) against pcl::KdTreeFLANN, build + one radius query per point, on a real
// KITTI 04 scan after range cut and 0.4 m voxel downsampling (synthetic street if absent).
//
//   cmake -S . -B build -DJVL_BUILD_BENCHMARKS=ON
//   cmake --build build -j2 --target lidar_benchmark && build/bin/lidar_benchmark
#include <benchmark/benchmark.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <filesystem>

#include "io/dataset.h"
#include "lidar/preprocess.h"
#include "lidar/surface.h"
#include "lidar/test_scenes.h"
#include "lidar/voxel_grid.h"

namespace {

using jvl::lidar::PointGrid;

const std::vector<Eigen::Vector3d>& Points() {
  static const std::vector<Eigen::Vector3d> points = [] {
    const std::string seq =
        std::string(JVL_SOURCE_DIR) + "/../shared/data/kitti_odometry_04_f0-50/sequences/04";
    std::vector<Eigen::Vector3d> raw;
    if (std::filesystem::exists(seq)) {
      const auto dataset = jvl::io::OpenDataset(seq);
      for (const auto& p : dataset->LoadScan(5).points) {
        if (p.norm() >= 5) raw.push_back(p);
      }
    } else {
      raw = jvl::lidar::testing::StreetScene(0.1);
    }
    std::vector<Eigen::Vector3d> out;
    for (const size_t i : jvl::lidar::VoxelDownsample(raw, 0.4)) out.push_back(raw[i]);
    return out;
  }();
  return points;
}

constexpr double kRadius = 1.0;

void BM_GridBatchedRadius(benchmark::State& state) {
  const auto& pts = Points();
  for (auto _ : state) {
    const PointGrid grid(pts, kRadius);
    int64_t found = 0;
    grid.ForEachCell(1, [&](const std::vector<int>& members, const std::vector<int>& cand) {
      for (const int i : members) {
        for (const int j : cand) found += (pts[j] - pts[i]).squaredNorm() <= kRadius * kRadius;
      }
    });
    benchmark::DoNotOptimize(found);
  }
  state.counters["points"] = static_cast<double>(pts.size());
}
BENCHMARK(BM_GridBatchedRadius)->Unit(benchmark::kMillisecond);

void BM_GridPerPointRadius(benchmark::State& state) {
  const auto& pts = Points();
  std::vector<std::pair<double, int>> out;
  for (auto _ : state) {
    const PointGrid grid(pts, kRadius);
    int64_t found = 0;
    for (const auto& p : pts) {
      grid.RadiusSearch(p, kRadius, 0, &out);
      found += static_cast<int64_t>(out.size());
    }
    benchmark::DoNotOptimize(found);
  }
}
BENCHMARK(BM_GridPerPointRadius)->Unit(benchmark::kMillisecond);

void BM_PclKdTreeRadius(benchmark::State& state) {
  const auto& pts = Points();
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : pts) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  pcl::Indices idx;
  std::vector<float> d2;
  for (auto _ : state) {
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    tree.setInputCloud(cloud);
    int64_t found = 0;
    for (const auto& p : *cloud) found += tree.radiusSearch(p, kRadius, idx, d2);
    benchmark::DoNotOptimize(found);
  }
}
BENCHMARK(BM_PclKdTreeRadius)->Unit(benchmark::kMillisecond);

void BM_ComputeSurface(benchmark::State& state) {
  const auto& pts = Points();
  for (auto _ : state) {
    const auto s = jvl::lidar::ComputeSurface(pts, jvl::lidar::SurfaceOptions(), 1);
    benchmark::DoNotOptimize(s.normals.data());
  }
}
BENCHMARK(BM_ComputeSurface)->Unit(benchmark::kMillisecond);

// The whole preprocessing (range cut, voxel filter, outliers, ground, small objects) of a raw
// scan of the KITTI 04 excerpt (skipped without it).
void BM_PreprocessScan(benchmark::State& state) {
  const std::string seq =
      std::string(JVL_SOURCE_DIR) + "/../shared/data/kitti_odometry_04_f0-50/sequences/04";
  if (!std::filesystem::exists(seq)) {
    state.SkipWithError("the KITTI 04 excerpt is not at ../shared/data");
    return;
  }
  const auto dataset = jvl::io::OpenDataset(seq);
  const jvl::PointCloud scan = dataset->LoadScan(5);
  for (auto _ : state) {
    const auto pre = jvl::lidar::PreprocessScan(scan, dataset->calibration().cam0_from_velo,
                                                jvl::lidar::PreprocessOptions(), 1);
    benchmark::DoNotOptimize(pre.points.data());
  }
}
BENCHMARK(BM_PreprocessScan)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
