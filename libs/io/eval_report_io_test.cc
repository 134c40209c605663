#include "io/eval_report_io.h"

#include <gtest/gtest.h>

#include <sstream>

#include "core/check.h"

namespace jvl::io {
namespace {

TEST(EvalReportIo, KittiMatricesAreKeptAsWritten) {
  // A rotation block that is orthonormal only to ~1e-7, as in KITTI files: kept untouched.
  std::istringstream in(
      "2 1.0000001 0 0 1.5 0 1 0 2.5 0 0 1 3.5\n"
      "# comment\n"
      "4 1 0 0 0 0 1 0 0 0 0 1 7\n");
  const PoseMatrices m = ParsePoseMatricesKitti(in, "est.txt");
  ASSERT_EQ(m.frames, std::vector<int64_t>({2, 4}));
  EXPECT_EQ(m.poses[0](0, 0), 1.0000001);
  EXPECT_EQ(m.poses[0](2, 3), 3.5);
  EXPECT_EQ(m.poses[1](3, 3), 1.0);
  EXPECT_TRUE(m.timestamps.empty());
}

TEST(EvalReportIo, BadLinesNameFileAndLine) {
  std::istringstream decreasing(
      "5 1 0 0 0 0 1 0 0 0 0 1 0\n"
      "3 1 0 0 0 0 1 0 0 0 0 1 0\n");
  try {
    ParsePoseMatricesKitti(decreasing, "est.txt");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("est.txt:2: frame 3 does not increase"), std::string::npos);
  }
  std::istringstream columns("1 2 3\n");
  EXPECT_THROW(ParsePoseMatricesKitti(columns, "x.txt"), Error);
  EXPECT_THROW(ReadPoseMatrices("/nonexistent/poses.txt"), Error);
}

}  // namespace
}  // namespace jvl::io
