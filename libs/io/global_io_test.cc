#include "io/global_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/check.h"
#include "core/temp_dir.h"
#include "io/ply_io.h"
#include "io/schema_check.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

class GlobalIoTest : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return dir_.Path(name); }
  TempDir dir_{"jvl_global_io"};
};

GlobalData Sample() {
  GlobalData d;
  for (int f = 0; f < 6; ++f) {
    const Rigid3d p(ExpSO3(Eigen::Vector3d(0, 0.01 * f, 0)), Eigen::Vector3d(0, 0, f));
    d.prior.Append(f, p, 0.1 * f);
    d.trajectory.Append(f, Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.1, 0, f)),
                        0.1 * f);
    if (f % 2 == 0) d.keyframes.Append(f, d.trajectory.world_from_cam.back());
  }
  d.stats = {{"weights", {{"alpha", 1.0}, {"beta", 3.5}, {"gamma", 20.0}}}};
  return d;
}

TEST_F(GlobalIoTest, RoundTripMatchesSchema) {
  Provenance p;
  p.tool = "global_opt";
  WriteGlobalArtifact(Path("g.h5"), Sample(), p);
  const auto problems = CheckH5AgainstSchema(
      Path("g.h5"), std::string(JVL_SOURCE_DIR) + "/schemas/global.schema.json");
  EXPECT_TRUE(problems.empty()) << problems.front();
  const GlobalData d = ReadGlobalArtifact(Path("g.h5"));
  ASSERT_EQ(d.keyframes.size(), 3u);
  EXPECT_EQ(d.keyframes.frames[2], 4);
  ASSERT_EQ(d.trajectory.size(), 6u);
  EXPECT_DOUBLE_EQ(d.trajectory.world_from_cam[5].translation().z(), 5.0);
  EXPECT_DOUBLE_EQ(d.trajectory.timestamps[3], 0.3);
  EXPECT_NEAR(d.prior.world_from_cam[5].rotation().angularDistance(
                  Sample().prior.world_from_cam[5].rotation()),
              0.0, 1e-12);
  EXPECT_DOUBLE_EQ(d.stats["weights"]["gamma"].get<double>(), 20.0);
}

TEST_F(GlobalIoTest, RejectsKeyframesOutsideTheTrajectory) {
  GlobalData d = Sample();
  d.keyframes.Append(9, Rigid3d());
  WriteGlobalArtifact(Path("bad.h5"), d, Provenance{});
  EXPECT_THROW(ReadGlobalArtifact(Path("bad.h5")), Error);
}

TEST_F(GlobalIoTest, PlyRoundTripBinaryAndAscii) {
  const std::vector<Eigen::Vector3f> pts = {{1, 2, 3}, {-4.5f, 0.25f, 1e3f}, {0, 0, 0}};
  for (const bool binary : {true, false}) {
    WritePly(Path("m.ply"), pts, binary);
    const auto back = ReadPly(Path("m.ply"));
    ASSERT_EQ(back.size(), pts.size());
    for (size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(back[i], pts[i]);
  }
  std::ifstream in(Path("m.ply"));
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "ply");
  EXPECT_EQ(fs::file_size(Path("m.ply")) > 0, true);
  WritePly(Path("b.ply"), pts, true);
  // Header + 3 vertices of 12 bytes.
  std::ifstream b(Path("b.ply"), std::ios::binary);
  const std::string all((std::istreambuf_iterator<char>(b)), std::istreambuf_iterator<char>());
  EXPECT_EQ(all.size() - (all.find("end_header\n") + 11), 36u);
}

}  // namespace
}  // namespace jvl::io
