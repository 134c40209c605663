// KITTI 04 (a straight road): ground-truth poses as the prior and VPs projected from the
// ground-truth forward direction with noise, building axes and outliers (the real detector's
// output is not used here).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "direction/direction_cluster.h"
#include "direction/synthetic_vps.h"
#include "io/artifact.h"
#include "io/directions_io.h"
#include "io/files.h"
#include "io/kitti.h"
#include "io/trajectory_io.h"
#include "io/vps_io.h"

namespace jvl::direction {
namespace {

const std::string kSeq = std::string(JVL_SOURCE_DIR) + "/../shared/data/kitti_odometry_04_f0-50";

class Kitti04 : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!io::FileExists(kSeq + "/poses/04.txt")) GTEST_SKIP() << kSeq << " is absent";
    gt_ = io::ReadTrajectory(kSeq + "/poses/04.txt");
    camera_ = io::ReadKittiCalibration(kSeq + "/sequences/04/calib.txt").Camera(0);
    camera_.width = 1226;
    camera_.height = 370;
    vps_ = testing::SimulateVpsFromMotion(gt_, camera_, {});
  }
  Trajectory gt_;
  PinholeCamera camera_;
  std::vector<VpObservation> vps_;
};

TEST_F(Kitti04, OneDominantClusterCoversTheStraightRoad) {
  const DirectionClusterResult r = ClusterDirections(vps_, gt_, camera_, {});
  ASSERT_FALSE(r.clusters.empty());
  int dominant = 0;
  for (const auto& c : r.clusters) dominant = std::max(dominant, c.size);
  const double coverage = double(dominant) / gt_.size();
  std::printf(
      "KITTI 04: %zu frames, %d VPs, %d forward, %zu clusters, dominant %d frames (%.1f %%)\n",
      gt_.size(), r.stats.input_vps, r.stats.forward_kept, r.clusters.size(), dominant,
      100 * coverage);
  for (const auto& c : r.clusters)
    std::printf("  cluster %d: %d frames %lld..%lld, std %.3f deg, d_w (%.4f %.4f %.4f)\n", c.id,
                c.size, (long long)c.first_frame, (long long)c.last_frame, c.std_deg,
                c.direction.x(), c.direction.y(), c.direction.z());
  EXPECT_GE(coverage, 0.8);
  // The dominant direction is the road's: start-to-end displacement on the ground.
  Eigen::Vector3d road =
      gt_.world_from_cam.back().translation() - gt_.world_from_cam[0].translation();
  road.y() = 0;
  for (const auto& c : r.clusters) {
    if (c.size != dominant) continue;
    Eigen::Vector3d d = c.direction;
    d.y() = 0;
    EXPECT_LT(std::acos(d.normalized().dot(road.normalized())) * 180 / M_PI, 1.0);
  }
}

TEST_F(Kitti04, VIntervalReducesAssociations) {
  DirectionClusterOptions o;
  std::map<int, int> counts;
  for (int k : {0, 5, 15, 50}) {
    o.v_interval = k;
    counts[k] = ClusterDirections(vps_, gt_, camera_, o).stats.associations;
    std::printf("KITTI 04 V_interval %2d: %d associations\n", k, counts[k]);
  }
  EXPECT_GT(counts[0], counts[5]);
  EXPECT_GT(counts[5], counts[15]);
  EXPECT_GT(counts[15], counts[50]);
  // A single cluster spanning ~270 frames keeps about 270 / K of them.
  EXPECT_NEAR(counts[50], 6, 2);
}

// Writes the projected VPs as a vps artifact (agreed layout) for running the tool end to end:
//   build/direction_demo/kitti04_vps.h5
TEST_F(Kitti04, WritesAVpsArtifactForTheTool) {
  const std::string dir = std::string(JVL_BINARY_DIR) + "/direction_demo";
  io::CreateDirectories(dir);
  io::VpsData data;
  data.frames = gt_.frames;
  data.camera = camera_;
  for (const auto& vp : vps_) {
    io::VpRecord r;
    r.frame = vp.frame;
    r.index = vp.vp_index;
    r.uv = vp.uv;
    r.direction = vp.direction_cam;
    r.score = vp.score;
    r.is_forward = vp.score == 1.0;  // The simulator gives the road VP score 1.
    data.vps.push_back(r);
  }
  io::Provenance p;
  p.tool = "direction_kitti_test";
  io::WriteVpsArtifact(dir + "/kitti04_vps.h5", data, p);
  EXPECT_EQ(io::ReadVpsArtifact(dir + "/kitti04_vps.h5").vps.size(), vps_.size());
}

}  // namespace
}  // namespace jvl::direction
