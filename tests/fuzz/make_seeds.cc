// Writes the seed corpus of artifact_fuzzer: one small valid artifact of every HDF5 schema.
//
//   make_seeds OUT_DIR      (the committed seeds are in tests/fuzz/corpus/artifact)
#include <cstdio>
#include <string>

#include "core/check.h"
#include "io/directions_io.h"
#include "io/global_io.h"
#include "io/local_io.h"
#include "io/odometry_io.h"
#include "io/trajectory_io.h"
#include "io/visual_io.h"
#include "io/vps_io.h"

namespace {

using namespace jvl;

Trajectory Line(int n) {
  Trajectory t;
  for (int i = 0; i < n; ++i)
    t.Append(i, Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, 1.0 * i}), 0.1 * i);
  return t;
}

PinholeCamera Camera() {
  PinholeCamera c;
  c.fx = c.fy = 700;
  c.cx = 600;
  c.cy = 180;
  c.width = 1226;
  c.height = 370;
  return c;
}

void WriteAll(const std::string& dir) {
  io::Provenance p;
  p.tool = "make_seeds";
  p.dataset_id = "kitti:00:00000000";
  io::WriteTrajectoryArtifact(dir + "/trajectory.h5", Line(3), p);

  io::OdometryArtifact odom;
  odom.trajectory = Line(3);
  auto& d = odom.diagnostics;
  d.iterations = {0, 5, 6};
  d.residual = {0, 0.1, 0.2};
  d.correspondences = {0, 900, 950};
  d.time_ms = {1, 50, 60};
  d.degenerate = {0, 0, 1};
  d.points_after_filter = {1000, 1000, 1000};
  d.status = {1, 0, 2};
  d.non_finite_points = {0, 0, 3};
  d.min_eigenvalue = {0, 0.5, 0.001};
  io::WriteOdometryArtifact(dir + "/odometry.h5", odom, p);

  io::VpsData vps;
  vps.frames = {0, 1};
  vps.camera = Camera();
  io::VpRecord r;
  r.frame = 1;
  r.uv = {600, 180};
  r.inliers = 40;
  r.is_forward = true;
  vps.vps = {r};
  io::WriteVpsArtifact(dir + "/vps.h5", vps, p);

  io::DirectionsData dirs;
  dirs.clusters.push_back({0, Eigen::Vector3d::UnitZ(), 0.3, 2, 0, 1, Eigen::Vector3d::Zero()});
  dirs.associations.push_back({1, 0, Eigen::Vector2d(600, 180), 0});
  io::WriteDirectionsArtifact(dir + "/directions.h5", dirs, p);

  io::VisualMapData v;
  v.camera = Camera();
  v.keyframes = Line(2);
  v.keypoint_keyframe = {0, 1};
  v.keypoint_uv = {10, 20, 11, 21};
  v.keypoint_octave = {0, 1};
  v.keypoint_angle = {0, 90};
  v.keypoint_descriptor.assign(64, 7);
  v.mappoint_position = {1, 2, 10};
  v.mappoint_descriptor.assign(32, 7);
  v.mappoint_normal = {0, 0, 1};
  v.observation_keyframe = {0, 1};
  v.observation_keypoint = {0, 1};
  v.observation_mappoint = {0, 0};
  v.covisibility_edges = {0, 1};
  v.covisibility_weight = {1};
  v.prior = Line(3);
  io::WriteVisualMap(dir + "/visual.h5", v, p);

  io::LocalMapData l;
  l.camera = Camera();
  l.keyframes = Line(2);
  l.imls_n = {1};
  l.imls_c = {0};
  l.imls_p_x = {1, 0, 5};
  l.imls_p_y = {1, 0, 6};
  l.imls_normal = {0, 0, 1};
  l.mappoint_position = {1, 2, 10};
  l.scan_offset = {0, 1, 2};
  l.scan_points = {1, 0, 5, 1, 0, 6};
  l.scan_normals = {0, 0, 1, 0, 0, 1};
  l.stats_frame = {0, 1};
  l.stats_visual_residuals = {0, 2};
  l.stats_imls_residuals = {0, 1};
  l.stats_cost_before = {0, 1};
  l.stats_cost_after = {0, 0.5};
  l.stats_time_ms = {0, 3};
  l.prior = Line(3);
  io::WriteLocalMap(dir + "/local.h5", l, p);

  io::GlobalData g;
  g.keyframes = Line(2);
  g.trajectory = Line(3);
  g.prior = Line(3);
  io::WriteGlobalArtifact(dir + "/global.h5", g, p);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_seeds OUT_DIR\n");
    return 2;
  }
  try {
    WriteAll(argv[1]);
  } catch (const jvl::Error& e) {
    std::fprintf(stderr, "make_seeds: error: %s\n", e.message().c_str());
    return 1;
  }
  return 0;
}
