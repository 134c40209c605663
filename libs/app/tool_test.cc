#include "app/tool.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <thread>
#include <utility>
#include <vector>

#include "app/option_group.h"
#include "core/check.h"
#include "core/temp_dir.h"
#include "io/files.h"
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
  const TempDir tmp("jvl_tool");
  const std::string dir = tmp.path().string();
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

// Runs a tool with an input option --in and output options -o and --also; returns the exit code
// and whether the body ran.
std::pair<int, bool> RunWithPaths(const std::vector<std::string>& args) {
  Tool tool("demo", "d");
  std::string in, out, also;
  tool.InputFile(tool.cli().add_option("--in", in, "input"));
  tool.OutputFile(tool.cli().add_option("-o,--output", out, "output"));
  tool.OutputFile(tool.cli().add_option("--also", also, "second output"));
  std::vector<const char*> argv = {"demo"};
  for (const std::string& a : args) argv.push_back(a.c_str());
  bool ran = false;
  const int code = tool.Run(static_cast<int>(argv.size()), argv.data(), [&] { ran = true; });
  return {code, ran};
}

TEST(ToolTest, OutputsThatAreInputsAreRefusedBeforeTheBody) {
  namespace fs = std::filesystem;
  const TempDir tmp("jvl_tool_out");
  const fs::path dir = tmp.path();
  fs::create_directories(dir / "sub");
  const std::string in = (dir / "in.txt").string();
  io::WriteTextFileAtomic(in, "input\n");
  fs::create_symlink(in, dir / "link.txt");
  fs::create_hard_link(in, dir / "hard.txt");
  const std::string out = (dir / "out.txt").string();
  EXPECT_EQ(RunWithPaths({"--in", in, "-o", out}), std::make_pair(0, true));
  for (const std::string& same :
       std::vector<std::string>{in, (dir / "sub" / ".." / "in.txt").string(),
                                (dir / "link.txt").string(), (dir / "hard.txt").string()}) {
    EXPECT_EQ(RunWithPaths({"--in", in, "-o", same}), std::make_pair(1, false)) << same;
  }
  // Two outputs on one path (one of them not existing yet), and an output that is a folder.
  EXPECT_EQ(RunWithPaths({"-o", out, "--also", (dir / "sub" / ".." / "out.txt").string()}),
            std::make_pair(1, false));
  EXPECT_EQ(RunWithPaths({"-o", (dir / "new.txt").string(), "--also", (dir / "new.txt").string()}),
            std::make_pair(1, false));
  EXPECT_EQ(RunWithPaths({"-o", (dir / "sub").string()}), std::make_pair(1, false));
  EXPECT_EQ(io::ReadTextFile(in), "input\n");
  {
    // An input recorded during the body is checked too.
    Tool tool("demo", "d");
    std::string output;
    tool.OutputFile(tool.cli().add_option("-o", output, "output"));
    const char* argv[] = {"demo", "-o", in.c_str()};
    EXPECT_EQ(tool.Run(3, argv, [&] { tool.AddInput(in); }), 1);
  }
  fs::remove_all(dir);
}

TEST(ToolTest, ConfigKeysUnsignedValuesAndThreadCountsAreChecked) {
  namespace fs = std::filesystem;
  const TempDir tmp("jvl_tool_cfg");
  const std::string config = tmp.Path("config.ini");
  io::WriteTextFileAtomic(config, "weight = 2\nno_such_key = 3\n");
  {
    Tool tool("demo", "d");
    double weight = 1;
    tool.cli().add_option("--weight", weight, "w");
    const char* argv[] = {"demo", "--config", config.c_str()};
    EXPECT_EQ(tool.Run(3, argv, [] {}), 2);  // unknown key
  }
  {
    Tool tool("demo", "d");
    uint64_t seed = 1;
    tool.cli().add_option("--seed", seed, "s");
    const char* argv[] = {"demo", "--seed", "-1"};
    EXPECT_EQ(tool.Run(3, argv, [] {}), 2);
    EXPECT_EQ(seed, 1u);
  }
  {
    Tool tool("demo", "d");
    const char* argv[] = {"demo", "--threads", "100000"};
    EXPECT_EQ(tool.Run(3, argv, [] {}), 0);
    const unsigned hw = std::thread::hardware_concurrency();
    if (hw > 0) {
      EXPECT_EQ(tool.threads(), static_cast<int>(hw));
    }
  }
  std::filesystem::remove(config);
}

TEST(ToolTest, ErrorsNameFlagsInsteadOfFields) {
  Tool tool("demo", "d");
  int samples = 1;
  double h = 1;
  tool.cli().add_option("--samples-per-list", samples, "s");
  tool.cli().add_option("--imls-h", h, "h");
  tool.FieldFlag("kernel_h", "--imls-h");
  testing::internal::CaptureStderr();
  const char* argv[] = {"demo"};
  EXPECT_EQ(tool.Run(1, argv,
                     [] {
                       JVL_THROW(
                           "samples_per_list must be >= 1 (kernel_h 0.3, max_distance "
                           "0.5, frames 2)");
                     }),
            1);
  const std::string err = testing::internal::GetCapturedStderr();
  // Fields with a flag become the flag; others (no such flag, plain words) stay.
  EXPECT_EQ(err,
            "demo: error: --samples-per-list must be >= 1 (--imls-h 0.3, max_distance 0.5, "
            "frames 2)\n");
}

// OptionGroup: options land in their group with the default shown, and an option added with its
// field name shows its flag in the tool's error line.
TEST(OptionGroup, GroupsDefaultsAndFieldNames) {
  Tool tool("demo", "d");
  int samples = 20;
  double h = 0.06;
  bool deskew = true;
  OptionGroup group(tool, "Registration");
  CLI::Option* s = group.Add("--samples-per-list", samples, "s");
  CLI::Option* k = group.Add("--imls-h", "kernel_h", h, "h");
  CLI::Option* d = group.Flag("--deskew,!--no-deskew", deskew, "deskew");
  EXPECT_EQ(s->get_group(), "Registration");
  EXPECT_EQ(k->get_group(), "Registration");
  EXPECT_EQ(d->get_group(), "Registration");
  EXPECT_EQ(s->get_default_str(), "20");
  EXPECT_EQ(k->get_default_str(), "0.06");
  testing::internal::CaptureStderr();
  const char* argv[] = {"demo", "--samples-per-list", "3"};
  EXPECT_EQ(tool.Run(3, argv, [] { JVL_THROW("kernel_h must be > 0, got 0"); }), 1);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "demo: error: --imls-h must be > 0, got 0\n");
  EXPECT_EQ(samples, 3);
}

// A switch with both spellings is recorded by the value it leaves, not by whether it was given,
// and --help names the default in words (CLI11's "--x,--no-x{false}" only says what --no-x sets).
TEST(OptionGroup, SwitchesRecordTheirValue) {
  for (const auto& [args, expected] :
       std::vector<std::pair<std::vector<const char*>, bool>>{
           {{"demo"}, true}, {{"demo", "--deskew"}, true}, {{"demo", "--no-deskew"}, false}}) {
    Tool tool("demo", "d");
    bool deskew = true;
    bool verbose = false;
    OptionGroup group(tool, "Registration");
    group.Flag("--deskew,!--no-deskew", deskew, "Deskew scans");
    group.Flag("--verbose", verbose, "Talk");
    EXPECT_EQ(tool.Run(static_cast<int>(args.size()), args.data(), [] {}), 0);
    EXPECT_EQ(deskew, expected);
    const auto j = tool.OptionsJson();
    EXPECT_EQ(j["deskew"], expected) << args.back();
    EXPECT_EQ(j["verbose"], false);
    const std::string help = tool.cli().help();
    EXPECT_NE(help.find("Deskew scans (default: on)"), std::string::npos) << help;
  }
}

}  // namespace
}  // namespace jvl::app
