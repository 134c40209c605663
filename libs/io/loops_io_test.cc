#include "io/loops_io.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/temp_dir.h"
#include "io/schema_check.h"

namespace jvl::io {
namespace {

std::string TempPath(const std::string& name) {
  static const TempDir dir("jvl_loops_io");
  return dir.Path(name);
}

LoopsData Sample() {
  LoopsData d;
  d.keyframes = {0, 5, 10, 600, 605};
  LoopRecord a;
  a.query = 600;
  a.match = 5;
  a.status = 0;
  a.match_from_query =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY())),
              Eigen::Vector3d(0.4, 0.01, -1.2));
  a.score = 0.21;
  a.ring_key_distance = 0.13;
  a.yaw_deg = 174;
  a.correspondences = 880;
  a.residual = 0.031;
  LoopRecord b = a;
  b.detector = 1;
  b.inliers = 143;
  b.points.push_back({Eigen::Vector3d(1, -0.5, 12), Eigen::Vector2d(300.5, 120.25),
                      Eigen::Vector2d(310, 118), 0, 2});
  b.query = 605;
  b.match = 10;
  b.status = 4;
  d.loops = {a, b};
  return d;
}

TEST(LoopsIo, RoundTripSchemaAndCsv) {
  const std::string path = TempPath("rt.h5");
  const LoopsData in = Sample();
  WriteLoopsArtifact(path, in, Provenance{});
  const LoopsData out = ReadLoopsArtifact(path);
  EXPECT_EQ(out.keyframes, in.keyframes);
  ASSERT_EQ(out.loops.size(), 2u);
  EXPECT_EQ(out.loops[0].query, 600);
  EXPECT_EQ(out.loops[0].match, 5);
  EXPECT_EQ(out.loops[1].status, 4);
  EXPECT_EQ(out.loops[0].match_from_query.ToArray(), in.loops[0].match_from_query.ToArray());
  EXPECT_EQ(out.loops[0].yaw_deg, 174);
  EXPECT_EQ(out.loops[0].correspondences, 880);
  EXPECT_EQ(out.loops[1].detector, 1);
  EXPECT_EQ(out.loops[1].inliers, 143);
  EXPECT_TRUE(out.loops[0].points.empty());
  ASSERT_EQ(out.loops[1].points.size(), 1u);
  EXPECT_EQ(out.loops[1].points[0].p_match, Eigen::Vector3d(1, -0.5, 12));
  EXPECT_EQ(out.loops[1].points[0].match_uv, Eigen::Vector2d(300.5, 120.25));
  EXPECT_EQ(out.loops[1].points[0].query_uv, Eigen::Vector2d(310, 118));
  EXPECT_EQ(out.loops[1].points[0].query_octave, 2);
  EXPECT_TRUE(CheckH5AgainstSchema(path, std::string(JVL_SOURCE_DIR) + "/schemas/loops.schema.json")
                  .empty());
  const std::string csv = FormatLoopsCsv(out);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "query,match,detector,status,score,ring_key_distance,yaw_deg,correspondences,inliers,"
            "residual,tx,ty,tz");
  EXPECT_NE(csv.find("\n605,10,1,4,0.21,0.13,174,880,143,0.031,"), std::string::npos);
  std::filesystem::remove(path);
}

TEST(LoopsIo, RejectsALoopToALaterOrUnknownKeyframe) {
  const std::string path = TempPath("bad.h5");
  LoopsData d = Sample();
  d.loops[0].match = 700;  // Not a keyframe, and after the query.
  WriteLoopsArtifact(path, d, Provenance{});
  EXPECT_THROW(ReadLoopsArtifact(path), std::exception);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace jvl::io
