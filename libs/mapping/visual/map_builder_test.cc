#include "mapping/visual/map_builder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "core/check.h"
#include "mapping/visual/visual_artifact.h"
#include "mapping/visual/visual_map.h"

namespace jvl::mapping {
namespace {

PinholeCamera KittiCamera() { return {718.856, 718.856, 607.1928, 185.2157, 1226, 370}; }

// A road corridor (two walls and the ground) seen by a camera driving forward at 1.4 m/frame.
// Each frame's features are the noisy projections of the visible points (descriptor with a few
// flipped bits, octave from the distance) plus confusers with copied descriptors elsewhere.
class Corridor {
 public:
  explicit Corridor(int frames) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> along(0, 1.4 * frames + 80), wall_y(-4, 1.6),
        ground_x(-7, 7), ref(30, 90);
    for (int i = 0; i < 6000; ++i) {
      const int kind = i % 3;
      const double z = along(rng);
      points_.push_back(kind == 0   ? Eigen::Vector3d(-7.5, wall_y(rng), z)
                        : kind == 1 ? Eigen::Vector3d(7.5, wall_y(rng), z)
                                    : Eigen::Vector3d(ground_x(rng), 1.65, z));
      vision::Descriptor d;
      for (auto& b : d) b = static_cast<uint8_t>(rng() & 0xff);
      descriptors_.push_back(d);
      reference_distance_.push_back(ref(rng));
    }
    for (int f = 0; f < frames; ++f) {
      poses_.Append(f, Rigid3d(ExpSO3(Eigen::Vector3d(0, 0.004 * f, 0)),
                               Eigen::Vector3d(0.02 * f, 0, 1.4 * f)));
    }
  }
  const Trajectory& poses() const { return poses_; }
  const Eigen::Vector3d& point(int i) const { return points_[i]; }

  vision::OrbFeatures View(int frame, std::vector<int>* truth) const {
    const PinholeCamera cam = KittiCamera();
    std::mt19937 rng(100 + frame);
    std::normal_distribution<double> noise(0.0, 0.3);
    std::uniform_real_distribution<float> u(0, 1226), v(0, 370);
    const Rigid3d cam_from_world = poses_.world_from_cam[frame].Inverse();
    vision::OrbFeatures f;
    truth->clear();
    auto add = [&](const Eigen::Vector2f& uv, int octave, const vision::Descriptor& d, int id) {
      f.keypoints.push_back({uv, octave, 10.f, 20.f});
      f.descriptors.push_back(d);
      truth->push_back(id);
    };
    for (size_t i = 0; i < points_.size(); ++i) {
      const Eigen::Vector3d p = cam_from_world * points_[i];
      if (p.z() < 1.0) continue;
      const int octave = std::clamp(
          static_cast<int>(
              std::floor(std::log(reference_distance_[i] / p.norm()) / std::log(1.2) + 0.5)),
          0, 7);
      const double s = std::pow(1.2, octave);
      const Eigen::Vector2d uv = cam.Project(p) + s * Eigen::Vector2d(noise(rng), noise(rng));
      if (!cam.InImage(uv, 20)) continue;
      vision::Descriptor d = descriptors_[i];
      for (int k = 0; k < 4; ++k) d[rng() % 32] ^= static_cast<uint8_t>(1u << (rng() % 8));
      add(uv.cast<float>(), octave, d, static_cast<int>(i));
      if (i % 4 == 0) add(Eigen::Vector2f(u(rng), v(rng)), octave, d, -1);  // Confuser.
    }
    return f;
  }

 private:
  std::vector<Eigen::Vector3d> points_;
  std::vector<vision::Descriptor> descriptors_;
  std::vector<double> reference_distance_;
  Trajectory poses_;
};

TEST(VisualMapBuilder, SyntheticCorridorWithKnownPoses) {
  const Corridor scene(30);
  VisualMapOptions options;
  options.keyframe.min_frames_between = 4;
  VisualMapBuilder builder(KittiCamera(), options);
  std::vector<std::vector<int>> truth(30);
  std::vector<FrameReport> reports;
  const std::vector<int64_t> direction_frames = {9, 10};
  for (int f = 0; f < 30; ++f) {
    const bool dir = std::count(direction_frames.begin(), direction_frames.end(), f) > 0;
    reports.push_back(
        builder.AddFrame(f, scene.poses().world_from_cam[f], scene.View(f, &truth[f]), dir));
  }
  // Direction frames are keyframes although consecutive (C2 with 4 frames would forbid it).
  EXPECT_TRUE(reports[9].keyframe);
  EXPECT_TRUE(reports[10].keyframe);
  EXPECT_EQ(reports[10].reason, KeyframeReason::kDirection);
  EXPECT_FALSE(reports[11].keyframe);

  const VisualMap map = builder.Finish();
  int good = 0, wrong = 0;
  std::vector<double> error_near;
  for (const MapPoint& p : map.points) {
    if (p.bad) continue;
    ++good;
    std::vector<int> ids;
    for (const Observation& o : p.observations) {
      ids.push_back(truth[map.keyframes[o.keyframe].frame][o.keypoint]);
    }
    const bool consistent = ids.front() >= 0 && std::all_of(ids.begin(), ids.end(), [&](int id) {
                              return id == ids.front();
                            });
    if (!consistent) {
      ++wrong;
      continue;
    }
    const Keyframe& first = map.keyframes[p.observations.front().keyframe];
    if ((first.cam_from_world * p.position).z() < 30) {
      error_near.push_back((p.position - scene.point(ids.front())).norm());
    }
  }
  std::sort(error_near.begin(), error_near.end());
  std::printf("corridor: %d points, %d inconsistent, %zu within 30 m, median error %.3f m\n", good,
              wrong, error_near.size(),
              error_near.empty() ? 0.0 : error_near[error_near.size() / 2]);
  ASSERT_GT(good, 1000);
  EXPECT_LT(wrong, 0.02 * good);
  // Tracking matches are gated by their reprojection and points lose outlying observations as
  // they are refined, so fewer near points survive than without those checks (446 vs > 500).
  ASSERT_GT(error_near.size(), 400u);
  // Median 3D error within 30 m; keypoint noise is 0.3 px x level scale (up to 1.1 px).
  EXPECT_LT(error_near[error_near.size() / 2], 0.10);

  const io::VisualMapData data = ExportVisualMap(map, scene.poses(), 15);
  data.Check("synthetic");
  const VisualMapStats stats = ComputeStats(data);
  EXPECT_LT(stats.median_reprojection_px, 1.0);
  EXPECT_GE(stats.min_points_per_keyframe, 100);
  EXPECT_GT(stats.edges, 0);
  for (int w : data.covisibility_weight) EXPECT_GE(w, 15);

  // Each keyframe's features come back from the artifact as they were extracted.
  const auto rows = KeypointRowsByFrame(data);
  ASSERT_EQ(rows.size(), map.keyframes.size());
  for (const Keyframe& kf : map.keyframes) {
    const auto [first, last] = rows.at(kf.frame);
    const vision::OrbFeatures back = KeyframeFeatures(data, first, last);
    ASSERT_EQ(back.keypoints.size(), kf.features.keypoints.size()) << "frame " << kf.frame;
    for (size_t i = 0; i < back.keypoints.size(); ++i) {
      EXPECT_EQ(back.keypoints[i].uv, kf.features.keypoints[i].uv);
      EXPECT_EQ(back.keypoints[i].octave, kf.features.keypoints[i].octave);
      EXPECT_EQ(back.keypoints[i].angle, kf.features.keypoints[i].angle);
      EXPECT_EQ(back.descriptors[i], kf.features.descriptors[i]);
    }
  }
  EXPECT_THROW(KeyframeFeatures(data, 0, data.num_keypoints() + 1), Error);
  // Keypoints not grouped by keyframe (one of the first keyframe's moved behind the second's)
  // and a keypoint of a keyframe that does not exist are refused.
  io::VisualMapData ungrouped = data;
  const size_t second_end = rows.at(map.keyframes[1].frame).second;
  std::swap(ungrouped.keypoint_keyframe[0], ungrouped.keypoint_keyframe[second_end - 1]);
  EXPECT_THROW(KeypointRowsByFrame(ungrouped), Error);
  io::VisualMapData outside = data;
  outside.keypoint_keyframe.back() = static_cast<int32_t>(data.keyframes.size());
  EXPECT_THROW(KeypointRowsByFrame(outside), Error);
}

// Heading error (deg) of a pose against the truth.
double HeadingErrorDeg(const Rigid3d& pose, const Rigid3d& truth) {
  return RotationAngle((truth.Inverse() * pose).rotation()) * 180.0 / M_PI;
}

// Every frame a keyframe (direction frames), so the map keeps the pose used for each frame.
VisualMap BuildAll(const Corridor& scene, const Trajectory& prior, const VisualMapOptions& options,
                   std::vector<FrameReport>* reports) {
  VisualMapBuilder builder(KittiCamera(), options);
  std::vector<int> truth;
  for (size_t f = 0; f < prior.size(); ++f) {
    reports->push_back(builder.AddFrame(prior.frames[f], prior.world_from_cam[f],
                                        scene.View(static_cast<int>(f), &truth), true));
  }
  return builder.Finish();
}

TEST(VisualMapBuilder, PoseTrackingRepairsAPriorGlitchAndLeavesAGoodPriorAlone) {
  const int frames = 20;
  const Corridor scene(frames);
  VisualMapOptions options;
  options.track_pose = true;
  // A correct prior: no refinement replaces it, the map is built at the prior's poses exactly.
  std::vector<FrameReport> reports;
  const VisualMap good = BuildAll(scene, scene.poses(), options, &reports);
  for (const FrameReport& r : reports) EXPECT_FALSE(r.pose_refined) << "frame " << r.frame;
  for (const Keyframe& kf : good.keyframes) {
    EXPECT_EQ(kf.world_from_cam.ToArray(), scene.poses().world_from_cam[kf.frame].ToArray());
  }
  // A registration glitch: frames 12-14 turned by 0.8 deg about the vertical, then back.
  Trajectory glitched = scene.poses();
  for (int f = 12; f <= 14; ++f) {
    glitched.world_from_cam[f] =
        glitched.world_from_cam[f] *
        Rigid3d(ExpSO3(Eigen::Vector3d(0, 0.8 * M_PI / 180, 0)), Eigen::Vector3d::Zero());
  }
  reports.clear();
  const VisualMap repaired = BuildAll(scene, glitched, options, &reports);
  reports.clear();
  options.track_pose = false;
  const VisualMap kept = BuildAll(scene, glitched, options, &reports);
  for (int f = 12; f <= 14; ++f) {
    EXPECT_NEAR(HeadingErrorDeg(kept.keyframes[f].world_from_cam, scene.poses().world_from_cam[f]),
                0.8, 1e-9);
    EXPECT_LT(
        HeadingErrorDeg(repaired.keyframes[f].world_from_cam, scene.poses().world_from_cam[f]), 0.1)
        << "frame " << f;
  }
  // After the glitch the prior's motion is right again, and the repaired frames stay on it.
  for (int f = 15; f < frames; ++f) {
    EXPECT_LT(
        HeadingErrorDeg(repaired.keyframes[f].world_from_cam, scene.poses().world_from_cam[f]), 0.1)
        << "frame " << f;
  }
}

TEST(VisualMapBuilder, RejectsFramesOutOfOrder) {
  const Corridor scene(3);
  VisualMapBuilder builder(KittiCamera(), VisualMapOptions());
  std::vector<int> truth;
  builder.AddFrame(1, scene.poses().world_from_cam[1], scene.View(1, &truth), false);
  EXPECT_THROW(builder.AddFrame(0, scene.poses().world_from_cam[0], scene.View(0, &truth), false),
               Error);
}

}  // namespace
}  // namespace jvl::mapping
