// Determinism of the whole chain on a short synthetic sequence (tests/robustness/pipeline.sh):
// runs a and b use one thread each and run t2 two; all three must give identical outputs (see
// artifact_compare.h for the run-time fields that are ignored, and docs/robustness.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "artifact_compare.h"
#include "io/files.h"

namespace jvl::testing {
namespace {

namespace fs = std::filesystem;

const std::string kDir = std::string(JVL_BINARY_DIR) + "/tests/robustness/";

std::vector<std::string> FilesUnder(const std::string& root) {
  std::vector<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file()) files.push_back(fs::relative(e.path(), root).string());
  std::sort(files.begin(), files.end());
  return files;
}

std::string Report(const CompareResult& r) {
  std::string s = std::to_string(r.difference_count) + " differences, max |diff| " +
                  std::to_string(r.max_abs_difference) + " at " + r.max_abs_where;
  for (const std::string& d : r.differences) s += "\n  " + d;
  return s;
}

class DeterminismTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const std::string run : {"run_a", "run_b", "run_t2"}) {
      if (!io::FileExists(kDir + run + "/metrics.json"))
        GTEST_SKIP() << kDir << run << " incomplete (robust_pipeline_* make it)";
    }
  }
};

TEST_F(DeterminismTest, SameThreadCountGivesIdenticalOutputs) {
  const auto files = FilesUnder(kDir + "run_a");
  ASSERT_EQ(files, FilesUnder(kDir + "run_b"));
  ASSERT_GT(files.size(), 100u);  // 40 scans, 40 images, the artifacts.
  for (const std::string& f : files) {
    const CompareResult r = CompareFiles(kDir + "run_a/" + f, kDir + "run_b/" + f, {});
    EXPECT_TRUE(r.equal) << f << ": " << Report(r);
  }
}

TEST_F(DeterminismTest, TwoThreadsMatchOneThread) {
  const auto files = FilesUnder(kDir + "run_a");
  ASSERT_EQ(files, FilesUnder(kDir + "run_t2"));
  // Every output is the same whatever the thread count: the parallel loops write per-item slots
  // and reduce in a fixed order, and Ceres runs on one thread (optim/joint_stats.cc). Only the
  // recorded option "threads" differs.
  CompareOptions options;
  options.ignored_options = {"threads"};
  for (const std::string& f : files) {
    const CompareResult r = CompareFiles(kDir + "run_a/" + f, kDir + "run_t2/" + f, options);
    EXPECT_TRUE(r.equal) << f << ": " << Report(r);
  }
}

}  // namespace
}  // namespace jvl::testing
