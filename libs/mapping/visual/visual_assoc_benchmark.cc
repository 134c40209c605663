// Speed of visual_assoc on real KITTI 04 frames 0-50 (needs ../shared/data):
//   BM_ExtractOrb          one 1226x370 image
//   BM_VisualAssocSequence the 51 frames with the ground truth prior, one thread; counters give
//                          the median per-frame time (ORB + association), the issue's <= 300 ms.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "core/statistics.h"
#include "io/dataset.h"
#include "io/trajectory_io.h"
#include "mapping/visual/map_builder.h"
#include "mapping/visual/visual_artifact.h"

namespace {

const std::string kRoot =
    std::string(JVL_BENCH_SOURCE_DIR) + "/../shared/data/kitti_odometry_04_f0-50";

void BM_ExtractOrb(benchmark::State& state) {
  const cv::Mat image =
      cv::imread(kRoot + "/sequences/04/image_0/000000.png", cv::IMREAD_GRAYSCALE);
  if (image.empty()) {
    state.SkipWithError("KITTI sample not found under ../shared/data");
    return;
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(jvl::vision::ExtractOrb(image, jvl::vision::OrbOptions()));
  }
}
BENCHMARK(BM_ExtractOrb)->Unit(benchmark::kMillisecond);

void BM_VisualAssocSequence(benchmark::State& state) {
  if (!std::filesystem::exists(kRoot)) {
    state.SkipWithError("KITTI sample not found under ../shared/data");
    return;
  }
  auto dataset = jvl::io::OpenDataset(kRoot + "/sequences/04");
  // Images are decoded once up front so that only ORB + association are timed.
  std::vector<cv::Mat> images;
  for (int64_t f : dataset->frames()) images.push_back(dataset->LoadImage(f, 0));
  const jvl::Trajectory prior = jvl::io::ReadTrajectory(kRoot + "/poses/04.txt");
  const jvl::Trajectory poses = jvl::mapping::SelectPriorPoses(prior, dataset->frames(), "04.txt");
  std::vector<double> frame_ms, orb_ms, assoc_ms;
  for (auto _ : state) {
    const auto result = jvl::mapping::BuildVisualMap(
        dataset->calibration().Camera(0), poses, {},
        [&](int64_t f) { return images[static_cast<size_t>(f - poses.frames.front())]; },
        jvl::mapping::VisualMapOptions(), 1);
    for (size_t i = 0; i < result.frames.size(); ++i) {
      frame_ms.push_back(result.frames[i].ms + result.orb_ms[i]);
      orb_ms.push_back(result.orb_ms[i]);
      assoc_ms.push_back(result.frames[i].ms);
    }
  }
  state.counters["frame_ms_median"] = jvl::UpperMedian(frame_ms);
  state.counters["frame_ms_max"] = *std::max_element(frame_ms.begin(), frame_ms.end());
  state.counters["orb_ms_median"] = jvl::UpperMedian(orb_ms);
  state.counters["assoc_ms_median"] = jvl::UpperMedian(assoc_ms);
  state.counters["frames"] = static_cast<double>(poses.size());
}
BENCHMARK(BM_VisualAssocSequence)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
