#include "io/directions_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/check.h"
#include "core/temp_dir.h"
#include "io/schema_check.h"
#include "io/vps_io.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

class DirectionsIoTest : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return dir_.Path(name); }
  static DirectionsData Sample() {
    DirectionsData d;
    d.clusters.push_back({0, {0, 0, 1}, 0.4, 2, 3, 9, {0, 1.5, 6}});
    d.clusters.push_back({1, {1, 0, 0}, 0.6, 1, 20, 20, {5, 1.5, 30}});
    d.associations.push_back({3, 0, {601.5, 183.25}, 0});
    d.associations.push_back({9, 2, {610, 180}, 0});
    d.associations.push_back({20, 1, {NAN, NAN}, 1});
    d.summary = {{"associations", 3}};
    return d;
  }
  TempDir dir_{"jvl_directions_io"};
};

TEST_F(DirectionsIoTest, RoundTripMatchesSchemaAndCsv) {
  Provenance p;
  p.tool = "direction_cluster";
  WriteDirectionsArtifact(Path("d.h5"), Sample(), p);
  const auto problems = CheckH5AgainstSchema(
      Path("d.h5"), std::string(JVL_SOURCE_DIR) + "/schemas/directions.schema.json");
  EXPECT_TRUE(problems.empty()) << problems.front();
  const DirectionsData d = ReadDirectionsArtifact(Path("d.h5"));
  ASSERT_EQ(d.clusters.size(), 2u);
  EXPECT_EQ(d.clusters[1].direction, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(d.clusters[0].last_frame, 9);
  EXPECT_EQ(d.clusters[0].centroid.z(), 6);
  ASSERT_EQ(d.associations.size(), 3u);
  EXPECT_EQ(d.associations[1].vp_index, 2);
  EXPECT_EQ(d.associations[0].uv.y(), 183.25);
  EXPECT_TRUE(std::isnan(d.associations[2].uv.x()));
  EXPECT_EQ(d.summary["associations"], 3);
  EXPECT_EQ(FormatDirectionsCsv(d),
            "frame,cluster,u,v,dwx,dwy,dwz\n"
            "3,0,601.500,183.250,0.000000000,0.000000000,1.000000000\n"
            "9,0,610.000,180.000,0.000000000,0.000000000,1.000000000\n"
            "20,1,nan,nan,1.000000000,0.000000000,0.000000000\n");
}

TEST_F(DirectionsIoTest, EmptyArtifactRoundTrips) {
  WriteDirectionsArtifact(Path("e.h5"), DirectionsData(), Provenance{});
  EXPECT_TRUE(CheckH5AgainstSchema(Path("e.h5"),
                                   std::string(JVL_SOURCE_DIR) + "/schemas/directions.schema.json")
                  .empty());
  EXPECT_TRUE(ReadDirectionsArtifact(Path("e.h5")).associations.empty());
}

TEST_F(DirectionsIoTest, RejectsTwoAssociationsInOneFrame) {
  DirectionsData d = Sample();
  d.associations[1].frame = 3;
  WriteDirectionsArtifact(Path("bad.h5"), d, Provenance{});
  try {
    ReadDirectionsArtifact(Path("bad.h5"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("frame 3 has more than one association"), std::string::npos);
  }
}

TEST_F(DirectionsIoTest, ReadsTheAgreedVpsLayout) {
  {
    H5Writer w(Path("vps.h5"), "vps", 1);
    w.WriteArray<int64_t>("frames", {0, 1});
    w.WriteArray<double>("camera", {700, 700, 600, 180, 1226, 370});
    w.WriteArray<int64_t>("vps/frame", {0, 1, 1});
    w.WriteArray<int32_t>("vps/index", {0, 0, 1});
    w.WriteArray<double>("vps/uv", {600, 180, 601, 181, NAN, NAN}, {3, 2});
    w.WriteArray<double>("vps/direction", {0, 0, 1, 0, 0, 1, 1, 0, 0}, {3, 3});
    w.WriteArray<int32_t>("vps/inliers", {30, 20, 10});
    w.WriteArray<double>("vps/residual_deg", {0.5, 0.6, 0.7});
    w.WriteArray<double>("vps/score", {1, 0.9, 0.5});
    w.WriteArray<uint8_t>("vps/is_forward", {1, 1, 0});
    w.Commit(Provenance{});
  }
  const VpsData v = ReadVpsArtifact(Path("vps.h5"));
  EXPECT_EQ(v.camera.width, 1226);
  ASSERT_EQ(v.vps.size(), 3u);
  EXPECT_EQ(v.vps[2].index, 1);
  EXPECT_EQ(v.vps[2].direction, Eigen::Vector3d(1, 0, 0));
  EXPECT_FALSE(v.vps[2].is_forward);
  EXPECT_EQ(v.vps[1].score, 0.9);
  EXPECT_THROW(ReadDirectionsArtifact(Path("vps.h5")), Error);
}

}  // namespace
}  // namespace jvl::io
