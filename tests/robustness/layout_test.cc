// The same simulated drive written in the KITTI odometry layout (run_a) and in the KITTI-360
// layout (run_k360, tests/robustness/pipeline.sh ... kitti360) goes through the whole chain to the
// same trajectories and metrics: the readers give the tools the same frames, timestamps,
// calibration, scans, images and ground truth. The calibration's numbers are written with 12
// (calib.txt) and 17 (KITTI-360 files) significant digits, so the poses may differ in the last
// bits: measured 1.5e-13 (odometry), 5.3e-13 (local_map) and 2.3e-12 (global_opt); the
// tolerance is 1e-9.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "io/files.h"
#include "io/trajectory_io.h"

namespace jvl::testing {
namespace {

const std::string kDir = std::string(JVL_BINARY_DIR) + "/tests/robustness/";
constexpr double kTolerance = 1e-9;

class LayoutTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const std::string run : {"run_a", "run_k360"}) {
      if (!io::FileExists(kDir + run + "/metrics.json"))
        GTEST_SKIP() << kDir << run << " incomplete (robust_pipeline_a / _k360 make it)";
    }
  }
};

TEST_F(LayoutTest, KittiAndKitti360LayoutsGiveTheSameTrajectories) {
  for (const std::string name : {"odom.txt", "local.txt", "global.txt"}) {
    const Trajectory a = io::ReadTrajectory(kDir + "run_a/" + name, io::TrajectoryFormat::kAuto);
    const Trajectory b = io::ReadTrajectory(kDir + "run_k360/" + name, io::TrajectoryFormat::kAuto);
    ASSERT_EQ(a.frames, b.frames) << name;
    ASSERT_GT(a.size(), 10u) << name;
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i) {
      worst = std::max(worst, (a.world_from_cam[i].Matrix3x4() - b.world_from_cam[i].Matrix3x4())
                                  .cwiseAbs()
                                  .maxCoeff());
    }
    EXPECT_LT(worst, kTolerance) << name;
  }
}

TEST_F(LayoutTest, KittiAndKitti360LayoutsGiveTheSameMetrics) {
  auto load = [](const std::string& run) {
    std::ifstream in(kDir + run + "/metrics.json");
    return nlohmann::json::parse(in);
  };
  const nlohmann::json a = load("run_a"), b = load("run_k360");
  ASSERT_EQ(a.at("estimates").size(), b.at("estimates").size());
  ASSERT_EQ(a["estimates"].size(), 4u);
  for (size_t i = 0; i < a["estimates"].size(); ++i) {
    const auto& ea = a["estimates"][i];
    const auto& eb = b["estimates"][i];
    EXPECT_EQ(ea["label"], eb["label"]);
    EXPECT_EQ(ea.at("frames_matched"), eb.at("frames_matched")) << ea["label"];
    for (const char* field : {"translation_m", "rotation_deg"}) {
      const double va = ea.at("ape").at(field).at("rmse").get<double>();
      const double vb = eb.at("ape").at(field).at("rmse").get<double>();
      EXPECT_NEAR(va, vb, kTolerance) << ea["label"] << " APE " << field;
    }
  }
}

}  // namespace
}  // namespace jvl::testing
