#include "io/odometry_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/check.h"
#include "core/temp_dir.h"
#include "io/schema_check.h"
#include "io/trajectory_io.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

OdometryArtifact MakeArtifact(int n) {
  OdometryArtifact a;
  for (int i = 0; i < n; ++i) {
    a.trajectory.Append(
        10 + i, Rigid3d(ExpSO3(Eigen::Vector3d(0, 0.01 * i, 0)), Eigen::Vector3d(0.1, 0, 1.2 * i)),
        0.1 * i);
    OdometryDiagnostics& d = a.diagnostics;
    d.iterations.push_back(i);
    d.residual.push_back(0.01 * i);
    d.correspondences.push_back(900 - i);
    d.time_ms.push_back(40.5 + i);
    d.degenerate.push_back(i == 2);
    d.points_after_filter.push_back(20000 + i);
    d.status.push_back(i == 0 ? 1 : (i == 2 ? 2 : 0));
    d.non_finite_points.push_back(i == 1 ? 7 : 0);
    d.min_eigenvalue.push_back(0.05);
  }
  return a;
}

std::string TempPath(const std::string& name) {
  static const TempDir dir("jvl_odometry_io");
  return dir.Path(name + ".h5");
}

TEST(OdometryIoTest, RoundTripAndTrajectoryReader) {
  const std::string path = TempPath("jvl_odom_rt_");
  const OdometryArtifact a = MakeArtifact(4);
  Provenance p;
  p.tool = "test";
  WriteOdometryArtifact(path, a, p);
  const OdometryArtifact b = ReadOdometryArtifact(path);
  EXPECT_EQ(b.trajectory.frames, a.trajectory.frames);
  EXPECT_EQ(b.diagnostics.status, a.diagnostics.status);
  EXPECT_EQ(b.diagnostics.degenerate, a.diagnostics.degenerate);
  EXPECT_EQ(b.diagnostics.non_finite_points, a.diagnostics.non_finite_points);
  EXPECT_DOUBLE_EQ(b.diagnostics.time_ms[3], 43.5);
  // Any stage that expects a trajectory can read the odometry artifact.
  const Trajectory t = ReadTrajectory(path);
  ASSERT_EQ(t.size(), 4u);
  EXPECT_NEAR(t.world_from_cam[3].translation().z(), 3.6, 1e-12);
  fs::remove(path);
}

// The conditioning read for the global optimisation's odometry term: the smallest eigenvalue of
// registered frames (status 0 ok, 2 degenerate), 0 for the first frame and motion-model frames;
// nothing from other trajectory files.
TEST(OdometryIoTest, ConditioningOfRegisteredFramesOnly) {
  const std::string path = TempPath("jvl_odom_cond_");
  OdometryArtifact a = MakeArtifact(4);
  a.diagnostics.status = {1, 0, 2, 3};
  a.diagnostics.min_eigenvalue = {0.0, 0.03, 0.001, 0.02};
  WriteOdometryArtifact(path, a, Provenance());
  EXPECT_EQ(ReadOdometryConditioning(path), (std::vector<double>{0.0, 0.03, 0.001, 0.0}));
  const std::string other = TempPath("jvl_odom_cond_traj_");
  WriteTrajectoryArtifact(other, a.trajectory, Provenance());
  EXPECT_TRUE(ReadOdometryConditioning(other).empty());
  const std::string kitti = other + ".txt";
  WriteTrajectoryKitti(kitti, a.trajectory);
  EXPECT_TRUE(ReadOdometryConditioning(kitti).empty());
  fs::remove(path);
  fs::remove(other);
  fs::remove(kitti);
}

TEST(OdometryIoTest, MismatchedDiagnosticsRejected) {
  OdometryArtifact a = MakeArtifact(3);
  a.diagnostics.residual.pop_back();
  try {
    WriteOdometryArtifact(TempPath("jvl_odom_bad_"), a, Provenance());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("diagnostics/residual"), std::string::npos) << e.message();
  }
}

// Every dataset the schema lists exists with its dtype and shape, nothing undocumented is
// written, and the provenance matches its schema.
TEST(OdometryIoTest, WrittenLayoutMatchesSchema) {
  const std::string path = TempPath("jvl_odom_schema_");
  WriteOdometryArtifact(path, MakeArtifact(5), Provenance());
  const auto problems =
      CheckH5AgainstSchema(path, std::string(JVL_SOURCE_DIR) + "/schemas/odometry.schema.json");
  EXPECT_TRUE(problems.empty()) << problems.front();
  fs::remove(path);
}

}  // namespace
}  // namespace jvl::io
