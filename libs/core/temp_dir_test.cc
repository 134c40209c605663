#include "core/temp_dir.h"

#include <gtest/gtest.h>

#include <fstream>

namespace jvl {
namespace {

TEST(TempDirTest, EachObjectHasItsOwnDirectoryRemovedWithIt) {
  std::filesystem::path kept;
  {
    TempDir a("jvl_temp_dir_test"), b("jvl_temp_dir_test");
    ASSERT_NE(a.path(), b.path());
    ASSERT_TRUE(std::filesystem::is_directory(a.path()));
    ASSERT_TRUE(std::filesystem::is_directory(b.path()));
    std::filesystem::create_directories(a.path() / "sub");
    std::ofstream(a.Path("sub/file.txt")) << "x";
    EXPECT_TRUE(std::filesystem::exists(a.path() / "sub" / "file.txt"));
    EXPECT_EQ(a.Path("f.h5"), (a.path() / "f.h5").string());
    kept = a.path();
  }
  EXPECT_FALSE(std::filesystem::exists(kept));
}

}  // namespace
}  // namespace jvl
