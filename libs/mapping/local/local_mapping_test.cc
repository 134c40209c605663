#include "mapping/local/local_mapping.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

#include "mapping/local/local_artifact.h"
#include "mapping/local/local_scan.h"
#include "mapping/local/local_test_scene.h"
#include "mapping/local/local_test_util.h"
#include "optim/cost_functions.h"

namespace jvl::mapping {
namespace {

using testing::DriftingPrior;
using testing::RoadPoses;
using testing::SampleScan;
using testing::StreetPatches;

const PinholeCamera kCamera{718.856, 718.856, 607.1928, 185.2157, 1226, 370};

// The motion over one frame period for de-skewing a keyframe's scan: centred (half of f-1 -> f+1)
// where both neighbours exist, one-sided at the ends, none without a neighbour.
TEST(LocalMapping, SweepMotionFromTheNeighbouringFrames) {
  Trajectory t;
  for (int f = 0; f < 4; ++f)
    t.Append(f,
             Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.02 * f * f, Eigen::Vector3d::UnitY())),
                     Eigen::Vector3d(0, 0, 1.0 * f * f)));
  const auto between = [&](int a, int b) {
    return t.world_from_cam[a].Inverse() * t.world_from_cam[b];
  };
  const auto centred = SweepMotion(t, 2);
  ASSERT_TRUE(centred.has_value());
  const Vector6d expected = 0.5 * LogSE3(between(1, 3));
  EXPECT_LT((LogSE3(*centred) - expected).norm(), 1e-12);
  ASSERT_TRUE(SweepMotion(t, 0).has_value());
  EXPECT_LT((LogSE3(*SweepMotion(t, 0)) - LogSE3(between(0, 1))).norm(), 1e-12);
  EXPECT_LT((LogSE3(*SweepMotion(t, 3)) - LogSE3(between(2, 3))).norm(), 1e-12);
  EXPECT_FALSE(SweepMotion(t, 10).has_value());
}

// A velodyne scan of flat ground 1.73 m below the sensor whose every return is reported
// `bias_deg` below the beam it was fired along (same range and azimuth: the HDL-64's elevation
// error, sim_sequence --lidar-elevation-bias).
PointCloud BiasedGroundScan(double bias_deg) {
  PointCloud scan;
  const double bias = bias_deg * M_PI / 180.0;
  for (int ring = 0; ring < 24; ++ring) {
    const double elevation = (-24.0 + ring * 0.9) * M_PI / 180.0;
    const double range = 1.73 / std::sin(-elevation);
    for (int a = 0; a < 3600; ++a) {
      const double azimuth = a * 0.1 * M_PI / 180.0;
      const double e = elevation - bias;
      scan.points.emplace_back(range * std::cos(e) * std::cos(azimuth),
                               range * std::cos(e) * std::sin(azimuth), range * std::sin(e));
    }
  }
  return scan;
}

// The stored scan's ground (cam0: y down) is flat when local_map's --vertical-correction undoes
// the bias, and a cone sinking with range without it: its mean slope (drop / horizontal
// distance) is tan(bias).
TEST(LocalMapping, KeyframeScanTakesTheElevationCorrection) {
  // KITTI's axes: cam0 x = -velo y, y = -velo z, z = velo x.
  Eigen::Matrix3d r;
  r << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const Rigid3d cam0_from_velo(Eigen::Quaterniond(r), Eigen::Vector3d::Zero());
  const PointCloud scan = BiasedGroundScan(0.2);
  const auto slope_deg = [&](double correction_deg) {
    ScanOptions options;
    options.preprocess.vertical_correction_deg = correction_deg;
    const KeyframeScan prepared = PrepareKeyframeScan(scan, cam0_from_velo, options, 100, 1);
    double sum = 0;
    int count = 0;
    for (const auto& p : prepared.stored.points) {
      const double d = std::hypot(p.x(), p.z());
      if (d < 10) continue;
      sum += (p.y() - 1.73) / d;
      ++count;
    }
    EXPECT_GT(count, 100);
    return std::atan(sum / std::max(count, 1)) * 180.0 / M_PI;
  };
  EXPECT_NEAR(slope_deg(0.0), 0.2, 0.01);
  EXPECT_NEAR(slope_deg(0.2), 0.0, 0.01);
  EXPECT_NEAR(slope_deg(0.4), -0.2, 0.01);  // over-corrected: a cone the other way
}

TEST(LocalMapping, StartKeyframeIsFirstWithinNFrames) {
  const std::vector<int64_t> frames{0, 3, 5, 9, 12, 20};
  EXPECT_EQ(StartKeyframe(frames, 0, 10, 1), 0u);  // Nothing before the first keyframe.
  EXPECT_EQ(StartKeyframe(frames, 4, 10, 1), 1u);  // 12 - 3 <= 10 < 12 - 0.
  EXPECT_EQ(StartKeyframe(frames, 3, 10, 1), 0u);  // 9 - 0 <= 10.
  EXPECT_EQ(StartKeyframe(frames, 5, 10, 1), 4u);  // 20 - 12 <= 10 < 20 - 9.
  EXPECT_EQ(StartKeyframe(frames, 5, 8, 1), 4u);   // Boundary: f_n - f_i == N is inside.
  EXPECT_EQ(StartKeyframe(frames, 5, 7, 0), 5u);   // Literal rule: empty S_model.
  EXPECT_EQ(StartKeyframe(frames, 5, 7, 1), 4u);   // At least the previous keyframe.
  EXPECT_EQ(StartKeyframe(frames, 5, 7, 2), 3u);
  EXPECT_EQ(StartKeyframe(frames, 1, 1, 3), 0u);  // Cannot go before row 0.
}

TEST(LocalMapping, LocalKeyframesAreCovisibleEarlierOnesByTime) {
  const auto adj = CovisibilityAdjacency(6, {{0, 1}, {1, 2}, {2, 4}, {3, 4}, {4, 5}, {1, 2}});
  EXPECT_EQ(LocalKeyframes(4, adj), (std::vector<int64_t>{2, 3, 4}));  // 5 has not arrived.
  EXPECT_EQ(LocalKeyframes(0, adj), (std::vector<int64_t>{0}));
  EXPECT_EQ(LocalKeyframes(1, adj), (std::vector<int64_t>{0, 1}));
  EXPECT_EQ(adj[1], (std::vector<int>{0, 2}));  // Duplicate edge merged.
}

TEST(LocalMapping, SavedCorrespondencesReusedOnlyWithinLocal) {
  std::vector<optim::ImlsCorrespondence> saved(5);
  const int64_t pairs[5][2] = {{1, 0}, {2, 1}, {4, 2}, {4, 3}, {3, 1}};
  for (int i = 0; i < 5; ++i) {
    saved[i].n = pairs[i][0];
    saved[i].c = pairs[i][1];
  }
  // Keyframe r's own entries (n = r): none for 0, [0, 1) for 1, [1, 2) for 2, [4, 5) for 3,
  // [2, 4) for 4.
  const std::vector<std::pair<size_t, size_t>> ranges = {{0, 0}, {0, 1}, {1, 2}, {4, 5}, {2, 4}};
  EXPECT_EQ(ReusableCorrespondences(saved, ranges, {2, 3, 4}), (std::vector<size_t>{2, 3}));
  EXPECT_EQ(ReusableCorrespondences(saved, ranges, {0, 1, 2}), (std::vector<size_t>{0, 1}));
  EXPECT_TRUE(ReusableCorrespondences(saved, ranges, {4}).empty());  // Needs both keyframes.
}

TEST(LocalMapping, GaugeFixesFirstKeyframeAndNonLocalPoses) {
  EXPECT_EQ(FixedKeyframes({2, 3, 4}, {1, 2, 3, 4}), (std::set<int64_t>{1}));
  EXPECT_EQ(FixedKeyframes({2, 3, 4}, {2, 3, 4}), (std::set<int64_t>{2}));  // Oldest local.
  EXPECT_EQ(FixedKeyframes({0, 1, 2}, {0, 1, 2}), (std::set<int64_t>{0}));
  EXPECT_EQ(FixedKeyframes({5}, {3, 4, 5}), (std::set<int64_t>{3, 4}));
}

// Scans sampled from exact planes: at the true poses every sampled point lies on the IMLS
// surface, so every new residual of Eq. (3) is zero.
TEST(LocalMapping, ImlsResidualIsZeroAtTrueConfiguration) {
  const auto patches = StreetPatches();
  const std::vector<Rigid3d> truth = RoadPoses(4, 4.5, 0.01);
  std::vector<KeyframeScan> scans;
  for (size_t k = 0; k < truth.size(); ++k) {
    std::vector<Eigen::Vector3d> p, n;
    SampleScan(patches, truth[k], 0.3, 40, 11 + static_cast<uint32_t>(k), &p, &n);
    scans.push_back(KeyframeScanFromSurface(p, n, 0.3));
  }
  const lidar::ImlsModel model =
      BuildScanModel({&scans[0], &scans[1], &scans[2]}, {0, 1, 2}, truth, 0.6);
  const auto corr = AssociateScan(3, scans[3], truth[3], model, truth, lidar::AssociationOptions());
  ASSERT_GT(corr.size(), 500u);
  std::map<int64_t, int> per_c;
  double max_abs = 0;
  for (const auto& l : corr) {
    EXPECT_EQ(l.n, 3);
    ASSERT_GE(l.c, 0);
    ASSERT_LE(l.c, 2);
    ++per_c[l.c];
    const optim::PointToImlsCost cost(l.p_x, l.c_p_y, l.c_normal, 1.0);
    const auto bn = truth[3].ToArray();
    const auto bc = truth[static_cast<size_t>(l.c)].ToArray();
    double r = 0;
    cost(bn.data(), bc.data(), &r);
    max_abs = std::max(max_abs, std::abs(r));
    EXPECT_NEAR(l.c_normal.norm(), 1.0, 1e-12);
  }
  EXPECT_LT(max_abs, 1e-4);     // The IMLS model stores single-precision points (0.1 mm here).
  EXPECT_GE(per_c.size(), 2u);  // c is the keyframe of the nearest model point, not always one.
  // Away from the truth the same correspondences are violated.
  const Rigid3d moved = truth[3] * Rigid3d(Eigen::Quaterniond::Identity(), {0.1, -0.05, 0.2});
  const auto shifted = AssociateScan(3, scans[3], moved, model, truth, lidar::AssociationOptions());
  double sum = 0;
  for (const auto& l : shifted) {
    const optim::PointToImlsCost cost(l.p_x, l.c_p_y, l.c_normal, 1.0);
    const auto bn = moved.ToArray();
    const auto bc = truth[static_cast<size_t>(l.c)].ToArray();
    double r = 0;
    cost(bn.data(), bc.data(), &r);
    sum += r * r;
  }
  EXPECT_GT(std::sqrt(sum / static_cast<double>(shifted.size())), 0.03);
}

struct SyntheticRun {
  std::vector<Rigid3d> truth, prior;
  LocalMappingInput input;
  LocalMappingResult result;
};

SyntheticRun RunSynthetic(int keyframes, double yaw_drift, double scale,
                          const LocalMappingOptions& options, int threads = 2) {
  SyntheticRun run;
  run.truth = RoadPoses(keyframes, 4.5, 0.004);
  run.prior = DriftingPrior(run.truth, yaw_drift, scale);
  std::vector<int64_t> frames;
  for (int k = 0; k < keyframes; ++k) frames.push_back(3 * k);
  run.input = testing::MakeVisualInput(kCamera, run.truth, run.prior, frames, 1500, 0.5, 7);
  const auto patches = StreetPatches();
  run.result = RunLocalMapping(
      run.input,
      [&](size_t row) {
        std::vector<Eigen::Vector3d> p, n;
        SampleScan(patches, run.truth[row], 0.3, 40, 100 + static_cast<uint32_t>(row), &p, &n);
        return KeyframeScanFromSurface(p, n, 0.5);
      },
      options, threads);
  return run;
}

TEST(LocalMapping, SyntheticDriftingPriorIsCorrected) {
  LocalMappingOptions options;
  const SyntheticRun run = RunSynthetic(20, 0.01, 1.04, options);
  const double prior_ape = testing::KeyframeApe(run.prior, run.truth);
  const double local_ape = testing::KeyframeApe(run.result.poses, run.truth);
  std::printf("synthetic drift: keyframe APE prior %.3f m -> local %.3f m\n", prior_ape, local_ape);
  EXPECT_GT(prior_ape, 1.0);
  EXPECT_LE(local_ape, 0.5 * prior_ape);
  EXPECT_LT(local_ape, 0.2);
  // The first keyframe is the gauge.
  EXPECT_LT((run.result.poses[0].translation() - run.truth[0].translation()).norm(), 1e-12);
  // Bookkeeping: L holds every keyframe's new correspondences in arrival order; the reused
  // count of keyframe n is what L held before n with both keyframes in K_local(n).
  const auto adj = CovisibilityAdjacency(run.input.size(), run.input.covisibility);
  size_t offset = 0;
  for (size_t n = 0; n < run.input.size(); ++n) {
    const KeyframeStats& s = run.result.stats[n];
    const auto local = LocalKeyframes(n, adj);
    const std::set<int64_t> local_set(local.begin(), local.end());
    int reusable = 0;
    for (size_t i = 0; i < offset; ++i) {
      const auto& l = run.result.correspondences[i];
      ASSERT_LT(l.n, static_cast<int64_t>(n));
      reusable += local_set.count(l.n) && local_set.count(l.c);
    }
    EXPECT_EQ(s.reused_correspondences, reusable) << "keyframe " << n;
    EXPECT_EQ(s.imls_residuals, s.new_correspondences + s.reused_correspondences);
    const size_t start = StartKeyframe(run.input.frames, n, options.scan_map_size, 1);
    for (int i = 0; i < s.new_correspondences; ++i) {
      const auto& l = run.result.correspondences[offset + static_cast<size_t>(i)];
      ASSERT_EQ(l.n, static_cast<int64_t>(n));
      ASSERT_GE(l.c, static_cast<int64_t>(start));
      ASSERT_LT(l.c, static_cast<int64_t>(n));
    }
    offset += static_cast<size_t>(s.new_correspondences);
    if (n > 0) {
      EXPECT_GT(s.new_correspondences, 100) << "keyframe " << n;
    }
  }
  EXPECT_EQ(offset, run.result.correspondences.size());
}

// With two threads the next keyframe's scan is prepared while the current one is solved; the
// result is the same, bit for bit, as on one thread.
TEST(LocalMapping, ScanPrefetchLeavesTheResultUnchanged) {
  const SyntheticRun one = RunSynthetic(12, 0.01, 1.04, LocalMappingOptions(), 1);
  const SyntheticRun two = RunSynthetic(12, 0.01, 1.04, LocalMappingOptions(), 2);
  ASSERT_EQ(one.result.poses.size(), two.result.poses.size());
  for (size_t k = 0; k < one.result.poses.size(); ++k) {
    EXPECT_EQ(one.result.poses[k].translation(), two.result.poses[k].translation()) << k;
    EXPECT_EQ(one.result.poses[k].rotation().coeffs(), two.result.poses[k].rotation().coeffs());
    EXPECT_EQ(one.result.stats[k].iterations, two.result.stats[k].iterations);
  }
  EXPECT_EQ(one.result.map_points, two.result.map_points);
  EXPECT_EQ(one.result.correspondences.size(), two.result.correspondences.size());
}

TEST(LocalMapping, ExactPriorStaysPut) {
  const SyntheticRun run = RunSynthetic(8, 0.0, 1.0, LocalMappingOptions());
  for (size_t k = 0; k < run.truth.size(); ++k) {
    EXPECT_LT((run.result.poses[k].translation() - run.truth[k].translation()).norm(), 0.02);
    EXPECT_LT(RotationAngle(run.result.poses[k].rotation() * run.truth[k].rotation().inverse()),
              1e-3);
  }
  const io::LocalMapData data = ExportLocalMap(run.input, run.result, Trajectory(), {});
  EXPECT_EQ(data.keyframes.size(), 8u);
  EXPECT_EQ(data.scan_offset.size(), 9u);
  EXPECT_EQ(data.num_correspondences(), run.result.correspondences.size());
  EXPECT_EQ(data.num_mappoints(), run.input.map_points.size());
  // Consuming the result gives the same arrays and leaves its scans and correspondences empty.
  LocalMappingResult moved = run.result;
  const io::LocalMapData consumed = ExportLocalMap(run.input, std::move(moved), Trajectory(), {});
  EXPECT_TRUE(moved.scans.empty() && moved.correspondences.empty());
  EXPECT_EQ(moved.poses.size(), run.result.poses.size());
  EXPECT_EQ(consumed.imls_n, data.imls_n);
  EXPECT_EQ(consumed.imls_c, data.imls_c);
  EXPECT_EQ(consumed.imls_p_x, data.imls_p_x);
  EXPECT_EQ(consumed.imls_p_y, data.imls_p_y);
  EXPECT_EQ(consumed.imls_normal, data.imls_normal);
  EXPECT_EQ(consumed.mappoint_position, data.mappoint_position);
  EXPECT_EQ(consumed.scan_offset, data.scan_offset);
  EXPECT_EQ(consumed.scan_points, data.scan_points);
  EXPECT_EQ(consumed.scan_normals, data.scan_normals);
  EXPECT_EQ(consumed.stats_frame, data.stats_frame);
  EXPECT_GT(data.num_scan_points(), 0u);
}

}  // namespace
}  // namespace jvl::mapping
