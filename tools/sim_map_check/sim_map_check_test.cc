// End-to-end: a short simulated sequence (images only) -> the visual map with the ground-truth
// prior (the library path of visual_assoc) -> map points on the true surface (issue #8:
// median <= 5 cm for depth < 30 m), through the library and through the command line.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>

#include "core/timer.h"
#include "io/artifact.h"
#include "io/dataset.h"
#include "io/files.h"
#include "io/schema_check.h"
#include "io/visual_io.h"
#include "map_check_run.h"
#include "mapping/visual/map_builder.h"
#include "mapping/visual/visual_artifact.h"
#include "sim/describe.h"
#include "sim/write_sequence.h"

namespace jvl::tools {
namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 30;

class SimMapCheckTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ =
        (fs::temp_directory_path() / ("sim_map_check_test_" + std::to_string(getpid()))).string();
    fs::create_directories(dir_);
    const Timer timer;
    sim::SequenceOptions opt;
    opt.frames = kFrames;
    opt.simulate_scans = false;
    world_ = sim::BuildWorld(opt).release();
    sim::WriteSequence(*world_, io::SequenceLayout{dir_, "00"}, 2, [] { return io::Provenance{}; });
    // What visual_assoc does with --prior poses/00.txt (the ground truth).
    const auto dataset = io::OpenDataset(SequenceDir());
    const mapping::VisualMapOptions options;
    const Trajectory poses =
        mapping::SelectPriorPoses(world_->ground_truth, dataset->frames(), "ground truth");
    const mapping::VisualMapResult result = mapping::BuildVisualMap(
        dataset->calibration().Camera(0), poses, {},
        [&](int64_t f) { return dataset->LoadImage(f, 0); }, options, 2);
    visual_ = new io::VisualMapData(mapping::ExportVisualMap(result.map, world_->ground_truth,
                                                             options.min_covisibility_weight));
    io::WriteVisualMap(Path("visual.h5"), *visual_, io::Provenance{});
    setup_seconds_ = timer.ElapsedSeconds();
  }
  static void TearDownTestSuite() {
    delete world_;
    delete visual_;
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  static std::string Path(const std::string& name) { return dir_ + "/" + name; }
  static std::string SequenceDir() { return dir_ + "/sequences/00"; }

  static std::string dir_;
  static sim::World* world_;
  static io::VisualMapData* visual_;
  static double setup_seconds_;
};

std::string SimMapCheckTest::dir_;
sim::World* SimMapCheckTest::world_ = nullptr;
io::VisualMapData* SimMapCheckTest::visual_ = nullptr;
double SimMapCheckTest::setup_seconds_ = 0;

// Moves every map point along its measuring ray: onto the true surface (onto_surface) or from
// where it is, then by `offset` alternately away from and towards the camera.
io::VisualMapData MoveAlongRays(const io::VisualMapData& visual, const MapCheckRunResult& r,
                                const sim::World& world, bool onto_surface, double offset) {
  io::VisualMapData moved = visual;
  const Rigid3d world_from_map = world.map_from_world.Inverse();
  for (size_t p = 0; p < r.views.size(); ++p) {
    const sim::PointView& v = r.views[p];
    const sim::SurfaceDistance& d = r.distances[p];
    if (v.keyframe < 0 || (onto_surface && !d.hit)) continue;
    const Eigen::Vector3d ray = v.point - v.camera_center;
    const double t = ray.norm() + (onto_surface ? d.along_ray : 0.0) + (p % 2 ? offset : -offset);
    const Eigen::Vector3d x = world_from_map * (v.camera_center + t * ray.normalized());
    for (int k = 0; k < 3; ++k) moved.mappoint_position[3 * p + k] = x[k];
  }
  return moved;
}

// The measurement itself: the map with every point put onto the true surface along its ray
// measures ~0; moved 0.3 m along the ray it measures exactly 0.3 m along the ray and fails the
// 5 cm threshold (the perpendicular part is 0.3 m x |cos| of the incidence angle).
TEST_F(SimMapCheckTest, SurfacePointsPassAndShiftedPointsFail) {
  const sim::SurfaceCheckOptions options;
  const MapCheckRunResult r = RunMapCheck(*world_, *visual_, options, 2);
  const MapCheckRunResult on =
      RunMapCheck(*world_, MoveAlongRays(*visual_, r, *world_, true, 0), options, 2);
  EXPECT_GT(on.summary.all.points, 1000);
  EXPECT_LT(on.summary.all.p90_perpendicular, 1e-3);
  EXPECT_LT(on.summary.all.p90_along, 1e-3);
  EXPECT_GT(on.summary.all.within_threshold, 0.99);
  const MapCheckRunResult off =
      RunMapCheck(*world_, MoveAlongRays(*visual_, r, *world_, true, 0.3), options, 2);
  EXPECT_NEAR(off.summary.all.median_along, 0.3, 1e-3);
  EXPECT_NEAR(off.summary.all.median_signed_along, 0.0, 0.3 + 1e-3);
  EXPECT_GT(off.summary.all.median_perpendicular, 0.05);
  EXPECT_LT(off.summary.all.within_threshold, 0.5);
}

// The figure of issue #8 on this short sequence: with the ground-truth prior and the default
// options the map's points lie within 5 cm of the true surface in the median for depth < 30 m
// (0.0435 m and 55 % within 5 cm here; 0.042 m on the whole demo drive, docs/visual_assoc.md).
TEST_F(SimMapCheckTest, GroundTruthPriorMapNearTheSurface) {
  RecordProperty("setup_seconds", std::to_string(setup_seconds_));
  const sim::SurfaceCheckOptions options;
  const MapCheckRunResult r = RunMapCheck(*world_, *visual_, options, 2);
  const sim::SurfaceDistanceStats& all = r.summary.all;
  std::printf("%lld points < 30 m: median %.4f m, p90 %.4f m, within 5 cm %.3f, no hit %lld\n",
              static_cast<long long>(all.points), all.median_perpendicular, all.p90_perpendicular,
              all.within_threshold, static_cast<long long>(all.no_hit));
  EXPECT_EQ(r.max_keyframe_position_error_m, 0.0);
  EXPECT_GT(all.points, 1000);
  EXPECT_LT(all.no_hit, all.points / 100 + 1);
  EXPECT_LE(all.median_perpendicular, 0.05);
  EXPECT_GT(all.within_threshold, 0.50);
  ASSERT_EQ(r.summary.bins.size(), 3u);
  for (const auto& b : r.summary.bins) EXPECT_GT(b.points, 100);
  // Most points' observations agree with one true surface point (within 3 sigma).
  const std::vector<double> consistency = KeypointConsistency(*world_, *visual_, r.views);
  ASSERT_EQ(consistency.size(), visual_->num_mappoints());
  const auto agree =
      std::count_if(consistency.begin(), consistency.end(), [](double e) { return e < 3; });
  EXPECT_GT(agree, static_cast<std::ptrdiff_t>(consistency.size() / 2));
  // Moving the real points 0.3 m along their rays makes the figure clearly worse.
  const MapCheckRunResult m =
      RunMapCheck(*world_, MoveAlongRays(*visual_, r, *world_, false, 0.3), options, 2);
  EXPECT_GT(m.summary.all.median_perpendicular, all.median_perpendicular + 0.03);
}

TEST_F(SimMapCheckTest, CommandLine) {
  const std::string exe = std::string(JVL_BINARY_DIR) + "/bin/sim_map_check";
  if (!io::FileExists(exe)) GTEST_SKIP() << exe << " not built";
  const std::string cmd = exe + " --sequence " + SequenceDir() + " --visual " + Path("visual.h5") +
                          " --json " + Path("report.json") + " --points-csv " + Path("points.csv") +
                          " --threads 2 --quiet";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const nlohmann::json report = io::ReadJsonArtifact(Path("report.json"), "sim_map_check", 1);
  EXPECT_TRUE(io::CheckJsonAgainstSchema(
                  report, std::string(JVL_SOURCE_DIR) + "/schemas/sim_map_check.schema.json")
                  .empty());
  const MapCheckRunResult r = RunMapCheck(*world_, *visual_, {}, 1);
  EXPECT_EQ(report["all"]["points"].get<int64_t>(), r.summary.all.points);
  EXPECT_EQ(report["all"]["median_perpendicular_m"].get<double>(),
            r.summary.all.median_perpendicular);
  EXPECT_EQ(report["depth_bins"].size(), 3u);
  const std::string csv = io::ReadTextFile(Path("points.csv"));
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'),
            static_cast<std::ptrdiff_t>(visual_->num_mappoints() + 1));
  // Bad input: one error line, non-zero exit.
  EXPECT_NE(std::system((exe + " --sequence " + Path("nowhere") + " --visual " + Path("visual.h5") +
                         " 2>/dev/null")
                            .c_str()),
            0);
  EXPECT_NE(std::system((exe + " --sequence " + SequenceDir() + " --visual " + SequenceDir() +
                         "/sim/scene.json 2>/dev/null")
                            .c_str()),
            0);
}

// The world is rebuilt with the terrain scale the sequence was made with; files written before
// the scale existed have none and mean 1.
TEST(WorldOptionsFromSceneTest, ReadsTheTerrainScale) {
  sim::SequenceOptions opt;
  opt.frames = 5;
  opt.simulate_scans = false;
  opt.render_images = false;
  opt.scene.terrain_scale = 0.0;
  const auto flat = sim::BuildWorld(opt);
  nlohmann::json scene = sim::DescribeScene(*flat);
  const sim::SequenceOptions o = WorldOptionsFromScene(scene, "scene.json");
  EXPECT_EQ(o.scene.terrain_scale, 0.0);
  const auto rebuilt = sim::BuildWorld(o);
  EXPECT_NO_THROW(CheckSameWorld(*rebuilt, scene, flat->ground_truth, "scene.json"));
  scene["terrain"].erase("scale");
  EXPECT_EQ(WorldOptionsFromScene(scene, "scene.json").scene.terrain_scale, 1.0);
  // The default (rolling) world is not the flat one.
  opt.scene.terrain_scale = 1.0;
  EXPECT_THROW(CheckSameWorld(*sim::BuildWorld(opt), sim::DescribeScene(*flat), flat->ground_truth,
                              "scene.json"),
               std::exception);
}
}  // namespace
}  // namespace jvl::tools
