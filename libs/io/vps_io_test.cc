#include "io/vps_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>

#include "core/check.h"
#include "core/temp_dir.h"
#include "io/files.h"

namespace jvl::io {
namespace {

VpsData Sample() {
  VpsData d;
  d.frames = {3, 4, 5};
  d.camera = {707.0912, 707.0912, 601.8873, 183.1104, 1226, 370};
  VpRecord a;
  a.frame = 3;
  a.index = 0;
  a.uv = {610.5, 180.25};
  a.direction = Eigen::Vector3d(0.01, -0.003, 1).normalized();
  a.inliers = 42;
  a.residual_deg = 0.4;
  a.score = 1234.5;
  a.is_forward = true;
  VpRecord b = a;
  b.index = 1;
  b.uv = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  b.direction = {1, 0, 0};
  b.is_forward = false;
  VpRecord c = a;
  c.frame = 5;
  d.vps = {a, b, c};  // Frame 4 has no VPs.
  return d;
}

std::string TempPath(const std::string& name) {
  static const TempDir dir("jvl_vps_io");
  return dir.Path(name);
}

TEST(VpsIo, RoundTrip) {
  const std::string path = TempPath("rt.h5");
  const VpsData in = Sample();
  WriteVpsArtifact(path, in, Provenance{});
  const VpsData out = ReadVpsArtifact(path);
  EXPECT_EQ(out.frames, in.frames);
  EXPECT_EQ(out.camera.width, 1226);
  EXPECT_DOUBLE_EQ(out.camera.cx, 601.8873);
  ASSERT_EQ(out.vps.size(), 3u);
  EXPECT_EQ(out.vps[1].index, 1);
  EXPECT_TRUE(std::isnan(out.vps[1].uv.x()));
  EXPECT_EQ(out.vps[0].direction, in.vps[0].direction);
  EXPECT_TRUE(out.vps[0].is_forward);
  EXPECT_FALSE(out.vps[1].is_forward);
  EXPECT_EQ(out.vps[2].frame, 5);
  std::filesystem::remove(path);
}

TEST(VpsIo, Csv) {
  const std::string csv = FormatVpsCsv(Sample());
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "frame,vp_index,u,v,dx,dy,dz,inliers,residual_deg,score,is_forward");
  EXPECT_NE(csv.find("\n3,0,610.5,180.25,"), std::string::npos);
  EXPECT_NE(csv.find("\n3,1,nan,nan,1,0,0,42,0.4,1234.5,0\n"), std::string::npos);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);
}

TEST(VpsIo, WrongSchemaNamesFile) {
  const std::string path = TempPath("wrong.h5");
  H5Writer w(path, "trajectory", 1);
  w.WriteArray("frames", std::vector<int64_t>{0});
  w.Commit(Provenance{});
  try {
    ReadVpsArtifact(path);
    FAIL() << "expected a schema error";
  } catch (const Error& e) {
    EXPECT_NE(e.message().find(path), std::string::npos);
    EXPECT_NE(e.message().find("vps"), std::string::npos);
  }
  std::filesystem::remove(path);
}

// Every dataset the schema lists exists with the listed rank and fixed sizes, and the symbolic
// sizes (F, M) are consistent across datasets.
TEST(VpsIo, MatchesSchemaFile) {
  const auto schema =
      nlohmann::json::parse(ReadTextFile(std::string(JVL_SOURCE_DIR) + "/schemas/vps.schema.json"));
  const std::string path = TempPath("schema.h5");
  // Camera 2's artifact also has the optional camera_index and camera_offset.
  for (const int camera : {0, 2}) {
    VpsData sample = Sample();
    if (camera == 2) sample.camera_choice = {2, Eigen::Vector3d(0.06, 0, 0.006)};
    WriteVpsArtifact(path, sample, Provenance{});
    H5Reader reader(path, "vps", 1);
    EXPECT_EQ(ReadVpsArtifact(path).camera_choice.index, camera);
    EXPECT_EQ(schema["properties"]["schema"]["const"], reader.schema());
    EXPECT_EQ(schema["properties"]["schema_version"]["const"], reader.schema_version());
    std::map<std::string, int64_t> symbols;
    int datasets = 0;
    for (const auto& [name, prop] : schema["properties"].items()) {
      if (!prop.contains("x-hdf5")) continue;
      const auto& required = schema["required"];
      if (std::find(required.begin(), required.end(), name) == required.end() &&
          !reader.Has(name)) {
        EXPECT_EQ(camera, 0) << name;
        continue;
      }
      ++datasets;
      ASSERT_TRUE(reader.Has(name)) << name;
      const std::vector<int64_t> dims = reader.Dims(name);
      const auto& shape = prop["x-hdf5"]["shape"];
      ASSERT_EQ(dims.size(), shape.size()) << name;
      for (size_t k = 0; k < dims.size(); ++k) {
        if (shape[k].is_number()) {
          EXPECT_EQ(dims[k], shape[k].get<int64_t>()) << name;
        } else {
          const auto [it, fresh] = symbols.emplace(shape[k].get<std::string>(), dims[k]);
          EXPECT_EQ(it->second, dims[k]) << name << " dim " << k;
        }
      }
    }
    EXPECT_EQ(datasets, camera == 0 ? 10 : 12);
    EXPECT_EQ(symbols["F"], 3);
    EXPECT_EQ(symbols["M"], 3);
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace jvl::io
