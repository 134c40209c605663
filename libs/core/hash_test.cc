#include "core/hash.h"

#include <gtest/gtest.h>

#include <cstring>

namespace jvl {
namespace {

TEST(HashTest, KnownFnv1aVectors) {
  // Reference values of the 64-bit FNV-1a function.
  Fnv1a64 empty;
  EXPECT_EQ(empty.Hex(), "cbf29ce484222325");
  Fnv1a64 a;
  a.Update("a", 1);
  EXPECT_EQ(a.Hex(), "af63dc4c8601ec8c");
  Fnv1a64 foobar;
  foobar.Update("foo", 3);
  foobar.Update("bar", 3);  // Incremental equals one-shot.
  EXPECT_EQ(foobar.Hex(), "85944171f73967e8");
}

}  // namespace
}  // namespace jvl
