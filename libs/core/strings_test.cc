#include "core/strings.h"

#include <gtest/gtest.h>

#include <clocale>
#include <cmath>

#include "core/check.h"

namespace jvl {
namespace {

TEST(StringsTest, SplitAndTrim) {
  EXPECT_EQ(Trim("  a b \r\n"), "a b");
  const auto tokens = SplitWhitespace(" 1.5\t-2  3e-3 ");
  ASSERT_EQ(tokens.size(), 3u);
  EXPECT_EQ(tokens[1], "-2");
  EXPECT_EQ(SplitWhitespace("a,b, c", true).size(), 3u);
}

TEST(StringsTest, ParseDoubleIsStrictAndLocaleIndependent) {
  std::setlocale(LC_NUMERIC, "de_DE.UTF-8");  // May not exist; parsing must not care.
  EXPECT_DOUBLE_EQ(*ParseDouble("1.25"), 1.25);
  EXPECT_DOUBLE_EQ(*ParseDouble("+3e2"), 300.0);
  EXPECT_DOUBLE_EQ(*ParseDouble("-4.5e-1"), -0.45);
  EXPECT_TRUE(std::isnan(*ParseDouble("nan")));
  EXPECT_FALSE(ParseDouble("1.2.3"));
  EXPECT_FALSE(ParseDouble("1,5"));
  EXPECT_FALSE(ParseDouble(""));
  EXPECT_FALSE(ParseDouble("abc"));
  std::setlocale(LC_NUMERIC, "C");
}

TEST(StringsTest, ParseInt) {
  EXPECT_EQ(*ParseInt("000042"), 42);
  EXPECT_FALSE(ParseInt("4.2"));
}

TEST(StringsTest, FrameRange) {
  const FrameRange all = ParseFrameRange("");
  EXPECT_TRUE(all.Contains(0));
  EXPECT_TRUE(all.Contains(100000));
  const FrameRange r = ParseFrameRange("10:20");
  EXPECT_FALSE(r.Contains(9));
  EXPECT_TRUE(r.Contains(10));
  EXPECT_TRUE(r.Contains(19));
  EXPECT_FALSE(r.Contains(20));
  EXPECT_TRUE(ParseFrameRange("5:").Contains(999));
  EXPECT_FALSE(ParseFrameRange(":5").Contains(5));
  EXPECT_THROW(ParseFrameRange("20:10"), Error);
  EXPECT_THROW(ParseFrameRange("abc"), Error);
  EXPECT_THROW(ParseFrameRange("-1:3"), Error);
}

TEST(StringsTest, FormatDoubleRoundTrips) {
  for (double v : {0.1, 1.0 / 3.0, -2.5e-17, 123456789.123456789}) {
    EXPECT_EQ(*ParseDouble(FormatDouble(v)), v);
  }
}

}  // namespace
}  // namespace jvl
