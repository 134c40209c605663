#include "app/tool.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "core/check.h"
#include "io/trajectory_io.h"

namespace jvl::app {
namespace {

TEST(ToolTest, RunsBodyAndRecordsOptions) {
  Tool tool("demo", "A demo tool.");
  double weight = 1.5;
  std::string out;
  tool.cli().add_option("--weight", weight, "A weight")->capture_default_str();
  tool.cli().add_option("-o,--output", out, "Output")->required();
  bool ran = false;
  const char* argv[] = {"demo", "-o", "x.h5", "--threads", "2"};
  EXPECT_EQ(tool.Run(5, argv, [&] { ran = true; }), 0);
  EXPECT_TRUE(ran);
  EXPECT_EQ(tool.threads(), 2);
  const auto j = tool.OptionsJson();
  EXPECT_EQ(j["output"], "x.h5");
  EXPECT_EQ(j["weight"], "1.5");
  EXPECT_EQ(tool.MakeProvenance().tool, "demo");
}

TEST(ToolTest, ErrorsBecomeExitCodes) {
  {
    Tool tool("demo", "d");
    const char* argv[] = {"demo", "--no-such-option"};
    EXPECT_EQ(tool.Run(2, argv, [] {}), 2);
  }
  {
    Tool tool("demo", "d");
    const char* argv[] = {"demo"};
    EXPECT_EQ(tool.Run(1, argv, [] { JVL_THROW("broken input"); }), 1);
  }
  {
    Tool tool("demo", "d");
    const char* argv[] = {"demo", "--threads", "-3"};
    EXPECT_EQ(tool.Run(3, argv, [] {}), 1);
  }
}

TEST(ToolTest, InputsOfDifferentSequencesAreRejected) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("jvl_tool_" + std::to_string(::getpid())))
          .string();
  Trajectory t;
  t.Append(0, Rigid3d());
  io::Provenance p;
  p.dataset_id = "kitti:04:aaaa";
  io::WriteTrajectoryArtifact(dir + "/a.h5", t, p);
  p.dataset_id = "kitti:05:bbbb";
  io::WriteTrajectoryArtifact(dir + "/b.h5", t, p);
  io::WriteTrajectoryKitti(dir + "/c.txt", t);
  {
    Tool tool("demo", "d");
    tool.AddInput(dir + "/a.h5");
    tool.AddInput(dir + "/c.txt");                                 // Text: no dataset id, accepted.
    EXPECT_EQ(tool.MakeProvenance().dataset_id, "kitti:04:aaaa");  // Inherited.
    try {
      tool.AddInput(dir + "/b.h5");
      ADD_FAILURE() << "mixed sequences accepted";
    } catch (const Error& e) {
      EXPECT_NE(e.message().find("b.h5 was made from sequence 'kitti:05:bbbb'"), std::string::npos)
          << e.message();
      EXPECT_NE(e.message().find("a.h5"), std::string::npos) << e.message();
    }
  }
  {
    Tool tool("demo", "d");
    tool.AddInput(dir + "/a.h5");
    EXPECT_THROW(tool.SetDatasetId("kitti:05:bbbb", "seq/05"), Error);
    tool.AddInput(dir + "/b.h5", /*same_dataset=*/false);  // evaluate: any sequence.
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace jvl::app
