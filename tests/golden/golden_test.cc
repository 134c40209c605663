// Golden-file tests of every stage (tests/golden/README.md).
//
// StageGolden: each output listed in goldens.txt, produced by the tools as a user runs them
// (tests/robustness/pipeline.sh on the synthetic drive, tests/golden/kitti_chain.sh on the KITTI
// excerpt), each with --threads 1 and --threads 2, is compared with its committed digest.
// GoldenCanFail: for every stage, one option that matters, changed, makes the comparison fail
// with a readable report. GoldenCompare: the comparison code itself.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "golden.h"
#include "io/artifact.h"
#include "io/files.h"
#include "io/trajectory_io.h"

namespace jvl::golden {
namespace {

namespace fs = std::filesystem;

const std::string kSource = std::string(JVL_SOURCE_DIR) + "/tests/golden/";
const std::string kBinary = std::string(JVL_BINARY_DIR);

struct Entry {
  std::string stage, fixture, artifact, golden;
};

std::vector<Entry> Manifest() {
  std::vector<Entry> entries;
  std::istringstream in(io::ReadTextFile(kSource + "goldens.txt"));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    Entry e;
    if (fields >> e.stage >> e.fixture >> e.artifact >> e.golden) entries.push_back(e);
  }
  return entries;
}

// The run folder of a fixture with `threads` threads.
std::string RunDir(const std::string& fixture, int threads) {
  if (fixture == "sim") return kBinary + "/tests/robustness/" + (threads == 1 ? "run_a" : "run_t2");
  return kBinary + "/tests/golden/kitti_" + std::to_string(threads);
}

// Complete runs end with metrics.json (the last step of both chains).
bool Complete(const std::string& dir) { return io::FileExists(dir + "/metrics.json"); }

struct Case {
  Entry entry;
  int threads;
};

std::vector<Case> Cases() {
  std::vector<Case> cases;
  for (const Entry& e : Manifest())
    for (const int threads : {1, 2}) cases.push_back({e, threads});
  return cases;
}

class StageGolden : public ::testing::TestWithParam<Case> {};

TEST_P(StageGolden, MatchesItsDigest) {
  const Case& c = GetParam();
  const std::string dir = RunDir(c.entry.fixture, c.threads);
  if (io::FileExists(dir + "/SKIPPED")) GTEST_SKIP() << io::ReadTextFile(dir + "/SKIPPED");
  ASSERT_TRUE(Complete(dir)) << dir << " is incomplete (its fixture test failed?)";
  const std::string golden_path = kSource + "data/" + c.entry.golden;
  ASSERT_TRUE(io::FileExists(golden_path))
      << golden_path << " missing: run scripts/update_goldens.sh";
  const nlohmann::json golden = nlohmann::json::parse(io::ReadTextFile(golden_path));
  const Comparison result = Compare(golden, Digest(dir + "/" + c.entry.artifact, c.entry.artifact),
                                    Tolerances::Load(kSource + "tolerances.json"));
  const std::string context = c.entry.stage + " " + c.entry.artifact + " (" + c.entry.fixture +
                              " fixture, --threads " + std::to_string(c.threads) + ")";
  EXPECT_TRUE(result.ok()) << result.Report(context)
                           << "If the change is intended: scripts/update_goldens.sh, and say why "
                              "in the commit message.";
  EXPECT_GT(result.values_compared, 0u);
}

std::string CaseName(const ::testing::TestParamInfo<Case>& info) {
  std::string name = info.param.entry.stage + "_" + info.param.entry.fixture + "_" +
                     fs::path(info.param.entry.golden).stem().string() + "_threads" +
                     std::to_string(info.param.threads);
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Goldens, StageGolden, ::testing::ValuesIn(Cases()), CaseName);

// --------------------------------------------------------------------------------------------
// Every golden can fail: one option that matters, changed, and the stage's output no longer
// matches, with a report that names the artifact, a field and the values.

struct Change {
  std::string stage, golden, command;  // command: run in the sim fixture's run_a folder
  std::string output;                  // relative to the work folder
};

class GoldenCanFail : public ::testing::TestWithParam<Change> {};

TEST_P(GoldenCanFail, WhenAnOptionThatMattersChanges) {
  const Change& c = GetParam();
  const std::string run = RunDir("sim", 1);
  ASSERT_TRUE(Complete(run)) << run << " is incomplete";
  const std::string work = kBinary + "/tests/golden/can_fail/" + c.stage;
  fs::remove_all(work);
  fs::create_directories(work);
  std::string command = c.command;
  for (size_t at; (at = command.find("BIN/")) != std::string::npos;)
    command.replace(at, 4, kBinary + "/bin/");
  for (size_t at; (at = command.find("OUT/")) != std::string::npos;)
    command.replace(at, 4, work + "/");
  const std::string full = "cd '" + run + "' && " + command +
                           " --threads 1 --log-level error > /dev/null 2>&1";
  ASSERT_EQ(std::system(full.c_str()), 0) << full;
  const nlohmann::json golden =
      nlohmann::json::parse(io::ReadTextFile(kSource + "data/" + c.golden));
  const std::string artifact = golden.value("artifact", "?");
  const Comparison result = Compare(golden, Digest(work + "/" + c.output, artifact),
                                    Tolerances::Load(kSource + "tolerances.json"));
  ASSERT_FALSE(result.ok()) << c.stage << ": the changed option left the golden matching";
  const std::string report = result.Report(c.stage + " " + artifact + " (changed option)", 3);
  std::printf("%s", report.c_str());  // what a user sees
  EXPECT_NE(report.find(artifact), std::string::npos) << report;
  EXPECT_NE(report.find("expected"), std::string::npos) << report;
  EXPECT_NE(report.find("found"), std::string::npos) << report;
  EXPECT_LT(std::count(report.begin(), report.end(), '\n'), 6) << "not a wall of numbers";
}

const Change kChanges[] = {
    {"sim_sequence", "sim/sim_sequence.json",
     "BIN/sim_sequence -o OUT/data --sequence 00 --seed 2 --frames 40 --quiet", "data"},
    {"make_prior", "sim/make_prior.json",
     "BIN/make_prior -g data/poses/00.txt -o OUT/prior.h5 --preset orbslam2 --seed 1", "prior.h5"},
    {"lidar_odom", "sim/lidar_odom.json",
     "BIN/lidar_odom --dataset data/sequences/00 -o OUT/odom.h5 --quiet --scan-map-size 3",
     "odom.h5"},
    {"vp_detect", "sim/vp_detect.json",
     "BIN/vp_detect --dataset data/sequences/00 -o OUT/vps.h5 --quiet --max-vps 1", "vps.h5"},
    {"direction_cluster", "sim/direction_cluster.json",
     "BIN/direction_cluster --vps vps.h5 --prior prior.h5 -o OUT/directions.h5 --v-interval 5",
     "directions.h5"},
    {"visual_assoc", "sim/visual_assoc.json",
     "BIN/visual_assoc --dataset data/sequences/00 --prior prior.h5 --directions directions.h5 "
     "-o OUT/visual.h5 --quiet --orb-features 1000",
     "visual.h5"},
    {"local_map", "sim/local_map.json",
     "BIN/local_map --visual visual.h5 --dataset data/sequences/00 -o OUT/local.h5 --quiet "
     "--samples-per-list 10",
     "local.h5"},
    {"global_opt", "sim/global_opt.json",
     "BIN/global_opt --local local.h5 --visual visual.h5 --directions directions.h5 "
     "-o OUT/global.h5 --gamma 5",
     "global.h5"},
    {"global_opt_no_directions", "sim/global_opt_no_directions.json",
     "BIN/global_opt --local local.h5 --visual visual.h5 --directions directions.h5 "
     "--no-direction -o OUT/global_nodir.h5 --alpha 4",
     "global_nodir.h5"},
    {"evaluate", "sim/evaluate.json",
     "BIN/evaluate --gt data/poses/00.txt --est prior.h5 --est odom.h5 --est global_nodir.h5 "
     "--est global.h5 --align none --json OUT/metrics.json",
     "metrics.json"},
};

INSTANTIATE_TEST_SUITE_P(Stages, GoldenCanFail, ::testing::ValuesIn(kChanges),
                         [](const ::testing::TestParamInfo<Change>& info) {
                           return info.param.stage;
                         });

// --------------------------------------------------------------------------------------------
// The comparison code on small artifacts made here.

class GoldenCompare : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = kBinary + "/tests/golden/compare";
    fs::create_directories(dir_);
    tolerances_path_ = dir_ + "/tolerances.json";
    io::WriteTextFileAtomic(tolerances_path_, R"({"rules": [
      {"match": "*:trajectory/poses", "abs": 1e-6, "why": "test rule"}]})");
  }
  Trajectory Line(int n, double step) const {
    Trajectory t;
    for (int i = 0; i < n; ++i)
      t.Append(10 + i, Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, step * i}));
    return t;
  }
  nlohmann::json DigestOf(const Trajectory& t, const std::string& file) {
    io::Provenance p;
    p.tool = "test";
    p.wall_time_s = static_cast<double>(file.size());  // differs between files: excluded
    io::WriteTrajectoryArtifact(dir_ + "/" + file, t, p);
    return Digest(dir_ + "/" + file, "traj.h5");
  }
  std::string dir_, tolerances_path_;
};

TEST_F(GoldenCompare, SameContentMatchesAndProvenanceIsExcluded) {
  const auto a = DigestOf(Line(100, 1.0), "a.h5");
  const auto b = DigestOf(Line(100, 1.0), "bb.h5");
  const Comparison c = Compare(a, b, Tolerances::Load(tolerances_path_));
  EXPECT_TRUE(c.ok()) << c.Report("same");
  EXPECT_GT(c.values_compared, 100u);
  EXPECT_FALSE(a["fields"].contains("@provenance"));
}

TEST_F(GoldenCompare, FloatsWithinTheirToleranceMatchAndBeyondAreReportedByFrame) {
  const auto golden = DigestOf(Line(100, 1.0), "a.h5");
  Trajectory t = Line(100, 1.0);
  t.world_from_cam[50] = Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, 50.0 + 5e-7});
  EXPECT_TRUE(Compare(golden, DigestOf(t, "b.h5"), Tolerances::Load(tolerances_path_)).ok());
  t.world_from_cam[50] = Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, 50.0 + 1e-3});
  const Comparison c = Compare(golden, DigestOf(t, "b.h5"), Tolerances::Load(tolerances_path_));
  ASSERT_FALSE(c.ok());
  const std::string report = c.Report("traj.h5");
  // Row 50 is not in the sample of 24 rows, so the column sum shows it.
  EXPECT_NE(report.find("trajectory/poses [sum over all rows, tz]"), std::string::npos) << report;
  EXPECT_NE(report.find("(test rule)"), std::string::npos) << report;
  // A sampled row (the last, frame 109) is reported by its frame and column name.
  t = Line(100, 1.0);
  t.world_from_cam[99] = Rigid3d(Eigen::Quaterniond::Identity(), {0.5, 0, 99.0});
  const std::string last =
      Compare(golden, DigestOf(t, "b.h5"), Tolerances::Load(tolerances_path_)).Report("traj.h5");
  EXPECT_NE(last.find("trajectory/poses [frame 109, tx]: expected 0, found 0.5"), std::string::npos)
      << last;
}

TEST_F(GoldenCompare, IntegersAreExactEvenOutsideTheSample) {
  const auto golden = DigestOf(Line(100, 1.0), "a.h5");
  Trajectory t = Line(100, 1.0);
  for (size_t i = 51; i < t.size(); ++i) t.frames[i] += 1;  // one gap, between frames 60 and 62
  const Comparison c = Compare(golden, DigestOf(t, "b.h5"), Tolerances::Load(tolerances_path_));
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.Report("x").find("trajectory/frames"), std::string::npos) << c.Report("x");
}

TEST_F(GoldenCompare, MissingAndNewFieldsAndShapesAreReported) {
  const auto golden = DigestOf(Line(100, 1.0), "a.h5");
  const Comparison shape =
      Compare(golden, DigestOf(Line(99, 1.0), "b.h5"), Tolerances::Load(tolerances_path_));
  EXPECT_NE(shape.Report("x").find("[shape]: expected [100,7], found [99,7]"), std::string::npos)
      << shape.Report("x");
  nlohmann::json other = golden;
  other["fields"].erase("trajectory/frames");
  other["fields"]["extra"] = {{"kind", "string"}, {"value", "x"}};
  const std::string report = Compare(golden, other, Tolerances::Load(tolerances_path_)).Report("x");
  EXPECT_NE(report.find("trajectory/frames: expected present, found missing"), std::string::npos)
      << report;
  EXPECT_NE(report.find("extra: expected missing, found present"), std::string::npos) << report;
}

TEST_F(GoldenCompare, JsonBodiesCompareByPathWithRunTimesExcluded) {
  const std::string a = dir_ + "/a.json", b = dir_ + "/b.json";
  io::WriteTextFileAtomic(a, R"({"n": 3, "x": 1.5, "median_time_ms": 10, "threads": 1,
    "provenance": {"created_utc": "now"}, "list": [1, 2]})");
  io::WriteTextFileAtomic(b, R"({"n": 3, "x": 1.5, "median_time_ms": 99, "threads": 2,
    "provenance": {"created_utc": "later"}, "list": [1, 2]})");
  const Tolerances none = Tolerances::Load(tolerances_path_);
  EXPECT_TRUE(Compare(Digest(a, "m.json"), Digest(b, "m.json"), none).ok());
  io::WriteTextFileAtomic(b, R"({"n": 4, "x": 1.5, "list": [1, 3]})");
  const std::string report = Compare(Digest(a, "m.json"), Digest(b, "m.json"), none).Report("m");
  EXPECT_NE(report.find("body [/n]: expected 3, found 4"), std::string::npos) << report;
  EXPECT_NE(report.find("body [/list[1]]: expected 2, found 3"), std::string::npos) << report;
}

}  // namespace
}  // namespace jvl::golden
