#include "core/progress.h"

#include <gtest/gtest.h>

namespace jvl {
namespace {

TEST(ProgressTest, LineShowsCountRateAndEta) {
  Progress progress("frames", 10, /*enabled=*/false);
  EXPECT_FALSE(progress.active());
  for (int i = 0; i < 4; ++i) progress.Tick();
  const std::string line = progress.Line();
  EXPECT_EQ(progress.done(), 4);
  EXPECT_NE(line.find("frames 4/10"), std::string::npos) << line;
  EXPECT_NE(line.find("frames/s"), std::string::npos) << line;
  EXPECT_NE(line.find("ETA"), std::string::npos) << line;
}

TEST(ProgressTest, FormatDuration) {
  EXPECT_EQ(FormatDuration(62), "1:02");
  EXPECT_EQ(FormatDuration(3723), "1:02:03");
  EXPECT_EQ(FormatDuration(-1), "?");
}

}  // namespace
}  // namespace jvl
