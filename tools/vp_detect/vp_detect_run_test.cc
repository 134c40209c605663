#include "vp_detect_run.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>

#include "core/temp_dir.h"
#include "io/files.h"
#include "io/vps_io.h"

namespace jvl {
namespace {

const std::string kSeq =
    std::string(JVL_SOURCE_DIR) + "/../shared/data/kitti_odometry_04_f0-50/sequences/04";

bool HaveData() { return std::filesystem::exists(kSeq + "/calib.txt"); }

void ExpectSameRecords(const io::VpsData& a, const io::VpsData& b) {
  ASSERT_EQ(a.vps.size(), b.vps.size());
  for (size_t i = 0; i < a.vps.size(); ++i) {
    EXPECT_EQ(a.vps[i].frame, b.vps[i].frame);
    EXPECT_EQ(a.vps[i].index, b.vps[i].index);
    EXPECT_EQ(a.vps[i].direction, b.vps[i].direction);
    EXPECT_EQ(a.vps[i].inliers, b.vps[i].inliers);
    EXPECT_EQ(a.vps[i].is_forward, b.vps[i].is_forward);
  }
}

TEST(VpDetectRun, ThreadsDoNotChangeTheResultAndOverlaysAreWritten) {
  if (!HaveData()) GTEST_SKIP() << "KITTI 04 subset not found at " << kSeq;
  cv::setNumThreads(1);
  const auto dataset = io::OpenDataset(kSeq, io::DatasetFormat::kAuto, ParseFrameRange("10:16"));
  VpDetectRunOptions options;
  options.progress = false;
  options.threads = 1;
  const VpDetectRunResult one = RunVpDetect(*dataset, options);
  options.threads = 2;
  const TempDir tmp("jvl_vp_detect_debug");
  const std::string debug = tmp.Path("debug");
  options.debug_dir = debug;
  const VpDetectRunResult two = RunVpDetect(*dataset, options);
  ExpectSameRecords(one.data, two.data);
  EXPECT_EQ(one.data.frames, (std::vector<int64_t>{10, 11, 12, 13, 14, 15}));
  EXPECT_EQ(one.data.camera.width, 1226);
  EXPECT_EQ(one.data.camera.height, 370);
  EXPECT_EQ(one.frames_with_forward, 6);
  for (int64_t f = 10; f < 16; ++f) {
    EXPECT_TRUE(io::FileExists(debug + "/0000" + std::to_string(f) + ".png")) << f;
  }
  // Rows are grouped by frame, indices count up from 0 within a frame.
  for (size_t i = 1; i < one.data.vps.size(); ++i) {
    const auto& p = one.data.vps[i - 1];
    const auto& c = one.data.vps[i];
    EXPECT_TRUE(c.frame > p.frame || (c.frame == p.frame && c.index == p.index + 1));
  }
  std::filesystem::remove_all(debug);
}

TEST(VpDetectRun, CommandLineWritesArtifactAndCsv) {
  const std::string exe = std::string(JVL_BINARY_DIR) + "/bin/vp_detect";
  if (!HaveData()) GTEST_SKIP() << "KITTI 04 subset not found at " << kSeq;
  if (!io::FileExists(exe)) GTEST_SKIP() << exe << " not built";
  const TempDir tmp("jvl_vp_cli");
  const std::string out = tmp.Path("vps.h5"), csv = tmp.Path("vps.csv");
  const std::string cmd = exe + " --dataset " + kSeq + " --frames 0:3 -o " + out + " --csv " + csv +
                          " --quiet --log-level warn";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const io::VpsData data = io::ReadVpsArtifact(out);
  EXPECT_EQ(data.frames, (std::vector<int64_t>{0, 1, 2}));
  EXPECT_EQ(io::ReadTextFile(csv), io::FormatVpsCsv(data));
  const std::string bad =
      exe + " --dataset " + kSeq + " -o " + out + " --detector hough 2>/dev/null";
  EXPECT_NE(std::system(bad.c_str()), 0);
  std::filesystem::remove(out);
  std::filesystem::remove(csv);
}

}  // namespace
}  // namespace jvl
