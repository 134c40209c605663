#include "loop/lidar_loops.h"

#include <gtest/gtest.h>

namespace jvl::loop {
namespace {

TEST(LidarLoops, RejectsBadOptions) {
  LidarLoopOptions o;
  o.max_descriptor_distance = 0;
  EXPECT_THROW(o.Check(), std::exception);
  o = LidarLoopOptions{};
  o.consistency = 0;
  EXPECT_THROW(o.Check(), std::exception);
  o = LidarLoopOptions{};
  o.verify_candidates = 0;
  EXPECT_THROW(o.Check(), std::exception);
}

}  // namespace
}  // namespace jvl::loop
