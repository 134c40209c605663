#include "io/trajectory_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "core/check.h"
#include "core/strings.h"
#include "core/temp_dir.h"
#include "io/files.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

Trajectory MakeTrajectory(int64_t first, int n, bool stamps) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    const Rigid3d pose(ExpSO3(Eigen::Vector3d(0.01 * i, 0.2 + 0.03 * i, -0.1)),
                       Eigen::Vector3d(1.0 / 3.0 + i, 0.5 * i, -2.25 * i));
    t.Append(first + i, pose, stamps ? std::optional<double>(1e9 + 0.1 * i) : std::nullopt);
  }
  return t;
}

void ExpectSame(const Trajectory& a, const Trajectory& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.frames[i], b.frames[i]);
    EXPECT_LE((a.world_from_cam[i].Matrix4() - b.world_from_cam[i].Matrix4()).norm(), tol);
  }
}

class TrajectoryIoTest : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return dir_.Path(name); }
  TempDir dir_{"jvl_traj_test"};
};

TEST_F(TrajectoryIoTest, KittiRoundTripIsExact) {
  const Trajectory t = MakeTrajectory(0, 20, false);
  WriteTrajectoryKitti(Path("a.txt"), t);
  // Contiguous frames from 0 give the 12-column form other tools read.
  const std::string text = ReadTextFile(Path("a.txt"));
  EXPECT_EQ(SplitWhitespace(text.substr(0, text.find('\n'))).size(), 12u);
  ExpectSame(ReadTrajectory(Path("a.txt")), t, 1e-12);
}

TEST_F(TrajectoryIoTest, IndexedKittiKeepsFrameIds) {
  const Trajectory t = MakeTrajectory(2, 5, false);
  WriteTrajectoryKitti(Path("b.txt"), t);
  const Trajectory r = ReadTrajectory(Path("b.txt"));
  EXPECT_EQ(r.frames.front(), 2);
  ExpectSame(r, t, 1e-12);
}

TEST_F(TrajectoryIoTest, TumRoundTripKeepsTimestamps) {
  const Trajectory t = MakeTrajectory(0, 7, true);
  WriteTrajectoryTum(Path("c.tum"), t);
  const Trajectory r = ReadTrajectory(Path("c.tum"));
  ASSERT_TRUE(r.has_timestamps());
  EXPECT_DOUBLE_EQ(r.timestamps[3], t.timestamps[3]);
  ExpectSame(r, t, 1e-12);
}

TEST_F(TrajectoryIoTest, H5RoundTripIsBitExact) {
  const Trajectory t = MakeTrajectory(10, 30, true);
  Provenance prov;
  prov.tool = "test";
  WriteTrajectoryArtifact(Path("d.h5"), t, prov);
  const Trajectory r = ReadTrajectory(Path("d.h5"));
  ExpectSame(r, t, 0.0);
  EXPECT_EQ(r.timestamps, t.timestamps);
  EXPECT_FALSE(FileExists(Path("d.h5") + ".tmp." + std::to_string(::getpid())));
}

TEST_F(TrajectoryIoTest, BadTextGivesLineNumber) {
  std::istringstream wrong_columns("1 0 0 0 0 1 0 0 0 0 1\n");
  try {
    ReadTrajectoryText(wrong_columns, TrajectoryFormat::kAuto, "x.txt");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("x.txt:1: 11 columns"), std::string::npos) << e.what();
  }
  std::istringstream nan_value("1 0 0 nan 0 1 0 0 0 0 1 0\n");
  EXPECT_THROW(ReadTrajectoryText(nan_value, TrajectoryFormat::kAuto, "y.txt"), Error);
  std::istringstream not_rotation("2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THROW(ReadTrajectoryText(not_rotation, TrajectoryFormat::kAuto, "z.txt"), Error);
  std::istringstream empty("# only a comment\n");
  EXPECT_THROW(ReadTrajectoryText(empty, TrajectoryFormat::kAuto, "e.txt"), Error);
  EXPECT_THROW(ReadTrajectory(Path("missing.txt")), Error);
}

}  // namespace
}  // namespace jvl::io
