#include "io/local_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

#include "core/check.h"
#include "core/temp_dir.h"
#include "io/schema_check.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

// Two keyframes, one correspondence, two map points, three scan points.
LocalMapData MakeLocal() {
  LocalMapData d;
  d.camera = {718.856, 718.856, 607.1928, 185.2157, 1226, 370};
  d.keyframes.Append(3, Rigid3d());
  d.keyframes.Append(5, Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1.5)));
  d.prior = d.keyframes;
  d.prior.Append(6, Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 2.5)));
  d.imls_n = {1};
  d.imls_c = {0};
  d.imls_p_x = {1.0, 2.0, 3.0};
  d.imls_p_y = {1.1, 2.1, 4.5};
  d.imls_normal = {0.0, -1.0, 0.0};
  d.mappoint_position = {0.5, -0.5, 10.0, 1.5, -0.25, 12.0};
  d.scan_offset = {0, 2, 3};
  d.scan_points = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  d.scan_normals = {0, -1, 0, 0, -1, 0, 1, 0, 0};
  d.stats_frame = {3, 5};
  d.stats_visual_residuals = {0, 120};
  d.stats_imls_residuals = {0, 450};
  d.stats_cost_before = {0, 12.5};
  d.stats_cost_after = {0, 3.25};
  d.stats_time_ms = {80, 310};
  d.summary = {{"keyframes", 2}};
  return d;
}

std::string TempPath(const std::string& name) {
  static const TempDir dir("jvl_local_io_test");
  return dir.Path(name);
}

TEST(LocalIo, RoundTripAndSchema) {
  const LocalMapData d = MakeLocal();
  const std::string path = TempPath("rt.h5");
  WriteLocalMap(path, d, Provenance{});
  const LocalMapData r = ReadLocalMap(path);
  EXPECT_EQ(r.camera.fx, d.camera.fx);
  EXPECT_EQ(r.keyframes.frames, d.keyframes.frames);
  EXPECT_NEAR(r.keyframes.world_from_cam[1].translation().z(), 1.5, 1e-15);
  EXPECT_EQ(r.prior.frames, d.prior.frames);
  EXPECT_EQ(r.imls_n, d.imls_n);
  EXPECT_EQ(r.imls_c, d.imls_c);
  EXPECT_EQ(r.imls_p_x, d.imls_p_x);
  EXPECT_EQ(r.imls_p_y, d.imls_p_y);
  EXPECT_EQ(r.imls_normal, d.imls_normal);
  EXPECT_EQ(r.mappoint_position, d.mappoint_position);
  EXPECT_EQ(r.scan_offset, d.scan_offset);
  EXPECT_EQ(r.scan_points, d.scan_points);
  EXPECT_EQ(r.scan_normals, d.scan_normals);
  EXPECT_EQ(r.stats_frame, d.stats_frame);
  EXPECT_EQ(r.stats_visual_residuals, d.stats_visual_residuals);
  EXPECT_EQ(r.stats_imls_residuals, d.stats_imls_residuals);
  EXPECT_EQ(r.stats_cost_before, d.stats_cost_before);
  EXPECT_EQ(r.stats_cost_after, d.stats_cost_after);
  EXPECT_EQ(r.stats_time_ms, d.stats_time_ms);
  EXPECT_EQ(r.summary.at("keyframes").get<int>(), 2);
  const auto problems =
      CheckH5AgainstSchema(path, std::string(JVL_SOURCE_DIR) + "/schemas/local.schema.json");
  for (const auto& p : problems) ADD_FAILURE() << p;
  fs::remove(path);
}

TEST(LocalIo, ReadsWithoutCorrespondences) {
  const LocalMapData d = MakeLocal();
  const std::string path = TempPath("scans.h5");
  WriteLocalMap(path, d, Provenance{});
  const LocalMapData r = ReadLocalMap(path, LocalMapParts::kWithoutCorrespondences);
  EXPECT_TRUE(r.imls_n.empty() && r.imls_c.empty() && r.imls_p_x.empty() && r.imls_p_y.empty() &&
              r.imls_normal.empty());
  EXPECT_TRUE(r.mappoint_position.empty());
  EXPECT_EQ(r.keyframes.frames, d.keyframes.frames);
  EXPECT_EQ(r.scan_offset, d.scan_offset);
  EXPECT_EQ(r.scan_points, d.scan_points);
  EXPECT_EQ(r.scan_normals, d.scan_normals);
  EXPECT_EQ(r.stats_frame, d.stats_frame);
  EXPECT_EQ(r.prior.frames, d.prior.frames);
  fs::remove(path);
}

TEST(LocalIo, ReadsWithoutScans) {
  const LocalMapData d = MakeLocal();
  const std::string path = TempPath("noscans.h5");
  WriteLocalMap(path, d, Provenance{});
  const LocalMapData r = ReadLocalMap(path, LocalMapParts::kWithoutScans);
  EXPECT_TRUE(r.scan_points.empty() && r.scan_normals.empty());
  EXPECT_EQ(r.scan_offset, d.scan_offset);
  EXPECT_EQ(r.imls_n, d.imls_n);
  EXPECT_EQ(r.imls_p_y, d.imls_p_y);
  EXPECT_EQ(r.mappoint_position, d.mappoint_position);
  EXPECT_EQ(r.stats_frame, d.stats_frame);
  fs::remove(path);
}

// Whatever the block size, the streamed scans are the file's rows, keyframe by keyframe.
TEST(LocalIo, StreamsScansInBlocks) {
  LocalMapData d = MakeLocal();
  // A third keyframe with an empty scan between two with points.
  d.keyframes.Append(7, Rigid3d());
  d.scan_offset = {0, 2, 2, 3};
  d.stats_frame.push_back(7);
  d.stats_visual_residuals.push_back(1);
  d.stats_imls_residuals.push_back(2);
  d.stats_cost_before.push_back(1);
  d.stats_cost_after.push_back(0.5);
  d.stats_time_ms.push_back(90);
  const std::string path = TempPath("stream.h5");
  WriteLocalMap(path, d, Provenance{});
  for (const int64_t block : {1, 2, 3, 1000}) {
    std::vector<size_t> keyframes;
    std::vector<float> points, normals;
    ReadLocalScans(
        path,
        [&](size_t keyframe, const float* p, const float* n, size_t rows) {
          EXPECT_EQ(rows, static_cast<size_t>(d.scan_offset[keyframe + 1] -
                                              d.scan_offset[keyframe]));
          keyframes.push_back(keyframe);
          points.insert(points.end(), p, p + 3 * rows);
          normals.insert(normals.end(), n, n + 3 * rows);
        },
        block);
    EXPECT_EQ(keyframes, (std::vector<size_t>{0, 1, 2})) << "block " << block;
    EXPECT_EQ(points, d.scan_points) << "block " << block;
    EXPECT_EQ(normals, d.scan_normals) << "block " << block;
  }
  EXPECT_THROW(ReadLocalScans(path, [](size_t, const float*, const float*, size_t) {}, 0), Error);
  fs::remove(path);
}

TEST(LocalIo, RejectsInconsistentData) {
  LocalMapData d = MakeLocal();
  d.imls_c = {2};  // Only two keyframes.
  EXPECT_THROW(WriteLocalMap(TempPath("bad.h5"), d, Provenance{}), Error);
  d = MakeLocal();
  d.scan_offset = {0, 2, 4};  // Three scan points only.
  EXPECT_THROW(WriteLocalMap(TempPath("bad.h5"), d, Provenance{}), Error);
  d = MakeLocal();
  d.stats_time_ms.pop_back();
  EXPECT_THROW(WriteLocalMap(TempPath("bad.h5"), d, Provenance{}), Error);
}

TEST(LocalIo, ReaderRejectsOtherSchema) {
  const std::string path = TempPath("other.h5");
  {
    H5Writer w(path, "visual", 1);
    w.WriteArray<double>("camera", {1, 2, 3, 4, 5, 6});
    w.Commit(Provenance{});
  }
  EXPECT_THROW(ReadLocalMap(path), Error);
  fs::remove(path);
}

}  // namespace
}  // namespace jvl::io
