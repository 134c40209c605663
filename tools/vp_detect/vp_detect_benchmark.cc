// Speed of vanishing point detection on real KITTI 04 images (1226x370), one core.
// Each iteration processes one image (cycling through frames 0-50). The counters give the median
// time per image and, for the line-detector comparison in docs/vp_detect.md, the median
// angular error of the forward VP against the ground-truth direction of travel over 20 m.
//
//   cmake -B build -DJVL_BUILD_BENCHMARKS=ON && cmake --build build --target vp_detect_benchmark
//   build/bin/vp_detect_benchmark
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <opencv2/core.hpp>

#include "io/dataset.h"
#include "io/trajectory_io.h"
#include "vision/vanishing_points.h"

namespace {

const std::string kRoot =
    std::string(JVL_SOURCE_DIR_BENCH) + "/../shared/data/kitti_odometry_04_f0-50";

struct Data {
  std::vector<cv::Mat> images;
  std::vector<Eigen::Vector3d> travel;  // GT direction of travel over 20 m, camera frame.
  jvl::PinholeCamera camera;
};

const Data& LoadData() {
  static const Data data = [] {
    Data d;
    if (!std::filesystem::exists(kRoot + "/sequences/04/calib.txt")) return d;
    const auto ds = jvl::io::OpenDataset(kRoot + "/sequences/04");
    const jvl::Trajectory gt = jvl::io::ReadTrajectory(kRoot + "/poses/04.txt");
    d.camera = ds->calibration().Camera(0);
    for (int64_t f : ds->frames()) {
      d.images.push_back(ds->LoadImage(f, 0));
      double path = 0;
      for (size_t k = f + 1; k < gt.size(); ++k) {
        path +=
            (gt.world_from_cam[k].translation() - gt.world_from_cam[k - 1].translation()).norm();
        if (path < 20.0) continue;
        const Eigen::Vector3d w =
            gt.world_from_cam[k].translation() - gt.world_from_cam[f].translation();
        d.travel.push_back((gt.world_from_cam[f].rotation().conjugate() * w).normalized());
        break;
      }
    }
    d.camera.width = d.images.front().cols;
    d.camera.height = d.images.front().rows;
    return d;
  }();
  return data;
}

double ThreadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * ts.tv_sec + 1e-6 * ts.tv_nsec;
}

double Median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// args: detector (0 = FLD, 1 = LSD), line scale in percent.
void BM_DetectVanishingPoints(benchmark::State& state) {
  cv::setNumThreads(1);
  const Data& data = LoadData();
  if (data.images.empty()) {
    state.SkipWithError("KITTI 04 subset not found under ../shared/data");
    return;
  }
  jvl::VpDetectOptions options;
  options.segments.detector =
      state.range(0) == 0 ? jvl::LineDetector::kFld : jvl::LineDetector::kLsd;
  options.segments.scale = state.range(1) / 100.0;
  // Accuracy: one untimed pass over all frames.
  std::vector<double> err_deg;
  size_t found = 0;
  for (size_t f = 0; f < data.images.size(); ++f) {
    const jvl::VpResult r = jvl::DetectVanishingPoints(data.images[f], data.camera, options);
    if (r.forward_index < 0) continue;
    ++found;
    const double c = std::clamp(r.vps[r.forward_index].direction.dot(data.travel[f]), -1.0, 1.0);
    err_deg.push_back(std::acos(c) * 180.0 / M_PI);
  }
  // Speed: wall time and the CPU time of this thread per image (the latter is what one core
  // costs when the machine is shared).
  std::vector<double> ms, cpu_ms;
  size_t i = 0;
  for (auto _ : state) {
    const size_t f = i++ % data.images.size();
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = ThreadCpuMs();
    benchmark::DoNotOptimize(jvl::DetectVanishingPoints(data.images[f], data.camera, options));
    cpu_ms.push_back(ThreadCpuMs() - c0);
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  state.counters["median_ms"] = Median(ms);
  state.counters["median_cpu_ms"] = Median(cpu_ms);
  state.counters["fwd_err_med_deg"] = Median(err_deg);
  std::sort(err_deg.begin(), err_deg.end());
  state.counters["fwd_err_p90_deg"] =
      err_deg.empty() ? std::nan("") : err_deg[err_deg.size() * 9 / 10];
  state.counters["fwd_found"] = static_cast<double>(found);
}

BENCHMARK(BM_DetectVanishingPoints)
    ->ArgNames({"lsd", "scale%"})
    ->Args({0, 50})
    ->Args({0, 100})
    ->Args({1, 50})
    ->Args({1, 80})
    ->Args({1, 100})
    ->MinTime(3.0)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
