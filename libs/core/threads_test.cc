#include "core/threads.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "core/check.h"

namespace jvl {
namespace {

TEST(ThreadsTest, ResolveThreadCount) {
  EXPECT_EQ(ResolveThreadCount(3), 3);
  EXPECT_GE(ResolveThreadCount(0), 1);
  EXPECT_THROW(ResolveThreadCount(-1), Error);
}

TEST(ThreadsTest, ParallelForVisitsEveryIndexOnce) {
  for (int threads : {1, 2, 4}) {
    std::vector<int> hits(1000, 0);
    ParallelFor(1000, threads, [&](int64_t i) { hits[i] += 1; });
    for (int h : hits) ASSERT_EQ(h, 1);
  }
}

TEST(ThreadsTest, ParallelForRethrows) {
  EXPECT_THROW(ParallelFor(100, 2,
                           [](int64_t i) {
                             if (i == 37) throw std::runtime_error("x");
                           }),
               std::runtime_error);
}

}  // namespace
}  // namespace jvl
