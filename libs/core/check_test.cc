#include "core/check.h"

#include <gtest/gtest.h>

namespace jvl {
namespace {

TEST(CheckTest, PassingCheckDoesNothing) { EXPECT_NO_THROW(JVL_CHECK(1 + 1 == 2, "math")); }

TEST(CheckTest, FailingCheckThrowsWithMessageAndLocation) {
  try {
    const int n = 17;
    JVL_CHECK(n % 16 == 0, "size " << n << " is not a multiple of 16");
    FAIL() << "expected an exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.message(), "size 17 is not a multiple of 16");
    const std::string what = e.what();
    EXPECT_NE(what.find("size 17 is not a multiple of 16 [core/check_test.cc:"), std::string::npos)
        << what;
  }
}

TEST(CheckTest, ThrowAlwaysThrows) { EXPECT_THROW(JVL_THROW("boom " << 3), Error); }

}  // namespace
}  // namespace jvl
