#include "core/statistics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace jvl {
namespace {

TEST(Statistics, MedianAveragesTheTwoMiddleValues) {
  EXPECT_DOUBLE_EQ(Median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(Median({4, 1, 3, 2}), 2.5);
  EXPECT_TRUE(std::isnan(Median({})));
}

TEST(Statistics, UpperMedianIsAnElementOfTheSample) {
  EXPECT_DOUBLE_EQ(UpperMedian({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(UpperMedian({4, 1, 3, 2}), 3.0);
  EXPECT_TRUE(std::isnan(UpperMedian({})));
}

TEST(Statistics, QuantileTakesTheNearestRank) {
  const std::vector<double> v = {10, 0, 5, 20, 15};  // sorted: 0 5 10 15 20
  EXPECT_DOUBLE_EQ(Quantile(v, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(Quantile(v, 0.5), 10.0);
  EXPECT_DOUBLE_EQ(Quantile(v, 0.9), 20.0);  // rank round(3.6) = 4
  EXPECT_DOUBLE_EQ(Quantile(v, 0.6), 10.0);  // rank round(2.4) = 2
  EXPECT_DOUBLE_EQ(Quantile(v, 2.0), 20.0);  // clamped
  EXPECT_TRUE(std::isnan(Quantile({}, 0.5)));
}

}  // namespace
}  // namespace jvl
