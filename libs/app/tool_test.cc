#include "app/tool.h"

#include <gtest/gtest.h>

#include "core/check.h"

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

}  // namespace
}  // namespace jvl::app
