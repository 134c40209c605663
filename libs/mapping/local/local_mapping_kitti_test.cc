// Real KITTI 04 (frames 0-50): lidar_odom N=1 prior -> visual map -> local mapping, and a
// drifting prior made from the ground truth. Figures printed for docs/local_map.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "core/temp_dir.h"
#include "core/timer.h"
#include "io/dataset.h"
#include "io/local_io.h"
#include "io/schema_check.h"
#include "io/trajectory_io.h"
#include "lidar/odometry.h"
#include "mapping/local/local_artifact.h"
#include "mapping/local/local_mapping.h"
#include "mapping/local/local_test_scene.h"
#include "mapping/local/local_test_util.h"
#include "mapping/visual/map_builder.h"
#include "mapping/visual/visual_artifact.h"
#include "mapping/visual/visual_map.h"

namespace jvl::mapping {
namespace {

namespace fs = std::filesystem;

const std::string kRoot = std::string(JVL_SOURCE_DIR) + "/../shared/data/kitti_odometry_04_f0-50";

struct KittiLocalRun {
  double prior_ape = 0, local_ape = 0, median_ms = 0;
  size_t keyframes = 0;
  LocalMappingInput input;
  LocalMappingResult result;
};

std::unique_ptr<io::Dataset> OpenKitti(const std::string& frames) {
  return io::OpenDataset(kRoot + "/sequences/04", io::DatasetFormat::kAuto,
                         ParseFrameRange(frames));
}

Trajectory LidarPrior(const io::Dataset& dataset, int scan_map_size) {
  lidar::OdometryOptions options;
  options.scan_map_size = scan_map_size;
  lidar::Odometry odometry(dataset.calibration().cam0_from_velo, options, 2);
  Trajectory t;
  for (size_t k = 0; k < dataset.frames().size(); ++k) {
    const auto f = odometry.ProcessScan(dataset.LoadScan(dataset.frames()[k]), dataset.frames()[k]);
    t.Append(f.frame, f.world_from_cam, dataset.timestamps().at(k));
  }
  return t;
}

KittiLocalRun RunKittiLocal(const io::Dataset& dataset, const Trajectory& prior,
                            const LocalMappingOptions& options) {
  const Trajectory gt = io::ReadTrajectory(kRoot + "/poses/04.txt");
  const VisualMapResult visual_result = BuildVisualMap(
      dataset.calibration().Camera(0), prior, {},
      [&](int64_t f) { return dataset.LoadImage(f, 0); }, VisualMapOptions(), 2);
  const io::VisualMapData visual = ExportVisualMap(visual_result.map, prior, 15);
  KittiLocalRun run;
  run.input = MakeLocalMappingInput(visual, prior, "prior");
  const LocalMappingInput& input = run.input;
  const Rigid3d cam0_from_velo = dataset.calibration().cam0_from_velo;
  run.result = RunLocalMapping(
      input,
      [&](size_t row) {
        return PrepareKeyframeScan(dataset.LoadScan(input.frames[row]), cam0_from_velo,
                                   ScanOptions(),
                                   LocalMappingOptions().association.samples_per_list, 2);
      },
      options, 2);
  std::vector<Rigid3d> truth;
  for (const int64_t f : input.frames) truth.push_back(gt.world_from_cam[*gt.IndexOf(f)]);
  run.keyframes = input.size();
  run.prior_ape = testing::KeyframeApe(input.prior, truth);
  run.local_ape = testing::KeyframeApe(run.result.poses, truth);
  std::vector<double> ms;
  for (const auto& s : run.result.stats) ms.push_back(s.time_ms);
  std::sort(ms.begin(), ms.end());
  run.median_ms = ms[ms.size() / 2];
  return run;
}

TEST(KittiLocal, LidarOdometryPriorIsNotMadeWorse) {
  if (!fs::exists(kRoot)) GTEST_SKIP() << "KITTI sample not found at " << kRoot;
  const auto dataset = OpenKitti("0:51");
  const Trajectory prior = LidarPrior(*dataset, 1);
  const KittiLocalRun run = RunKittiLocal(*dataset, prior, LocalMappingOptions());
  std::printf(
      "KITTI 04 0-50, lidar_odom N=1 prior: %zu keyframes, keyframe APE prior %.3f m -> "
      "local %.3f m, median %.0f ms per keyframe\n",
      run.keyframes, run.prior_ape, run.local_ape, run.median_ms);
  EXPECT_GE(run.keyframes, 8u);
  EXPECT_LE(run.local_ape, run.prior_ape * 1.0 + 1e-3);
  size_t optimized = 0;
  for (const auto& s : run.result.stats) optimized += s.optimized;
  EXPECT_GE(optimized, run.keyframes - 1);
  // The artifact of a real run matches its schema and reads back.
  const TempDir tmp("jvl_local_kitti_test");
  const std::string path = tmp.Path("local.h5");
  const LocalMappingOptions options;
  io::WriteLocalMap(
      path, ExportLocalMap(run.input, run.result, prior, SummarizeLocalMap(run.result, options)),
      io::Provenance{});
  for (const auto& p :
       io::CheckH5AgainstSchema(path, std::string(JVL_SOURCE_DIR) + "/schemas/local.schema.json")) {
    ADD_FAILURE() << p;
  }
  const io::LocalMapData back = io::ReadLocalMap(path);
  EXPECT_EQ(back.keyframes.frames, run.input.frames);
  EXPECT_EQ(back.num_correspondences(), run.result.correspondences.size());
  EXPECT_GT(back.num_scan_points(), 1000 * run.keyframes);
  fs::remove(path);
}

TEST(KittiLocal, DriftingPriorIsCorrected) {
  if (!fs::exists(kRoot)) GTEST_SKIP() << "KITTI sample not found at " << kRoot;
  const auto dataset = OpenKitti("0:51");
  const Trajectory gt = io::ReadTrajectory(kRoot + "/poses/04.txt");
  // A poor odometry: 0.1 deg of yaw and 3 % of scale error per frame on the true motion.
  Trajectory prior;
  std::vector<Rigid3d> truth;
  for (const int64_t f : dataset->frames()) truth.push_back(gt.world_from_cam[*gt.IndexOf(f)]);
  const auto drifted = testing::DriftingPrior(truth, 0.1 * M_PI / 180, 1.03);
  for (size_t k = 0; k < truth.size(); ++k) {
    prior.Append(dataset->frames()[k], drifted[k], dataset->timestamps().at(k));
  }
  const KittiLocalRun run = RunKittiLocal(*dataset, prior, LocalMappingOptions());
  std::printf(
      "KITTI 04 0-50, drifting prior (0.1 deg + 3 %% per frame): %zu keyframes, keyframe "
      "APE prior %.3f m -> local %.3f m, median %.0f ms per keyframe\n",
      run.keyframes, run.prior_ape, run.local_ape, run.median_ms);
  EXPECT_LE(run.local_ape, 0.5 * run.prior_ape);
}

}  // namespace
}  // namespace jvl::mapping
