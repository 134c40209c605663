// The bad-input matrix: every tool, run as a user runs it, on damaged datasets, damaged or
// mismatched artifacts and invalid options. Each case either fails with exit code 1 or 2 and
// exactly one "<tool>: error: ..." line on stderr naming the file, frame or option, or is a
// documented fallback that exits 0 with a warning (docs/robustness.md lists them). A crash, a
// hang (120 s) or a second error line fails the test.
//
// Inputs: the chain of run_a (robust_pipeline_a, 40 synthetic frames) and copies of its
// sequence with one thing broken each, under <build>/tests/robustness/bad.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "io/artifact.h"
#include "io/directions_io.h"
#include "io/files.h"
#include "io/kitti.h"
#include "io/local_io.h"
#include "io/trajectory_io.h"
#include "io/visual_io.h"
#include "io/vps_io.h"

namespace jvl {
namespace {

namespace fs = std::filesystem;

const std::string kBin = std::string(JVL_BINARY_DIR) + "/bin/";
const std::string kRun = std::string(JVL_BINARY_DIR) + "/tests/robustness/run_a";
const std::string kBad = std::string(JVL_BINARY_DIR) + "/tests/robustness/bad";
const std::string kSeq = kRun + "/data/sequences/00";

std::string In(const std::string& name) { return kRun + "/" + name; }
std::string Bad(const std::string& name) { return kBad + "/" + name; }

struct Outcome {
  int code = 0;
  std::string err;
};

// What must not change when a tool runs: every file named on its command line (by content) and
// every file under a folder named there (by size and modification time: datasets hold tens of
// MB). Outputs that the run is allowed to write are left out by the caller.
std::map<std::string, std::string> Snapshot(const std::string& args,
                                            const std::vector<std::string>& may_change) {
  std::map<std::string, std::string> snap;
  std::istringstream in(args);
  std::string token;
  const auto allowed = [&](const std::string& path) {
    for (const std::string& m : may_change)
      if (io::SameFile(m, path)) return true;
    return false;
  };
  while (in >> token) {
    std::error_code ec;
    if (fs::is_regular_file(token, ec)) {
      if (!allowed(token)) snap[token] = io::DescribeFile(token).hash;
    } else if (fs::is_directory(token, ec)) {
      for (const auto& e : fs::recursive_directory_iterator(token, ec)) {
        if (!e.is_regular_file() || allowed(e.path().string())) continue;
        const auto time = fs::last_write_time(e.path(), ec).time_since_epoch().count();
        snap[e.path().string()] =
            std::to_string(fs::file_size(e.path(), ec)) + "@" + std::to_string(time);
      }
    }
  }
  return snap;
}

Outcome Run(const std::string& tool, const std::string& args) {
  const std::string err_path = kBad + ".stderr.txt";  // beside kBad: not part of a snapshot
  const std::string log = args.find("--log-level") == std::string::npos ? " --log-level warn" : "";
  const std::string cmd = "timeout -k 5 120 " + kBin + tool + " " + args + " --quiet" + log +
                          " > /dev/null 2> " + err_path;
  const int status = std::system(cmd.c_str());
  Outcome o;
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  o.err = io::ReadTextFile(err_path);
  return o;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) lines.push_back(line);
  return lines;
}

// Fails with exit code 1/2 and one error line that contains `expected`; no file named on the
// command line (or under a folder named there) changes.
void ExpectError(const std::string& tool, const std::string& args, const std::string& expected) {
  const auto before = Snapshot(args, {});
  const Outcome o = Run(tool, args);
  const std::string what = tool + " " + args + "\nexit code " + std::to_string(o.code) +
                           (o.code == 124  ? " (hang)"
                            : o.code > 128 ? " (crash)"
                                           : "") +
                           "\nstderr:\n" + o.err;
  EXPECT_TRUE(o.code == 1 || o.code == 2) << what;
  std::vector<std::string> other;  // Lines that are not log lines ("[time] [level] ...").
  for (const std::string& line : Lines(o.err))
    if (line.front() != '[') other.push_back(line);
  EXPECT_TRUE(Snapshot(args, {}) == before) << "a file changed:\n" << what;
  ASSERT_EQ(other.size(), 1u) << what;
  std::printf("[error]   %s\n", other[0].c_str());  // The matrix, for docs/robustness.md.
  EXPECT_EQ(other[0].rfind(tool + ": error: ", 0), 0u) << what;
  EXPECT_NE(other[0].find(expected), std::string::npos) << "expected '" << expected << "' in\n"
                                                        << what;
}

// A documented fallback: exit code 0 and a warning that contains `expected`; every line on
// stderr is a log line, and no input changes (`outputs` may).
void ExpectWarning(const std::string& tool, const std::string& args, const std::string& expected,
                   const std::vector<std::string>& outputs = {Bad("x.h5")}) {
  const auto before = Snapshot(args, outputs);
  const Outcome o = Run(tool, args);
  const std::string what =
      tool + " " + args + "\nexit code " + std::to_string(o.code) + "\nstderr:\n" + o.err;
  EXPECT_EQ(o.code, 0) << what;
  EXPECT_TRUE(Snapshot(args, outputs) == before) << "an input changed:\n" << what;
  bool found = false;
  for (const std::string& line : Lines(o.err)) {
    EXPECT_EQ(line.front(), '[') << "not a log line: " << line << "\n" << what;
    if (line.find("[warning]") != std::string::npos && line.find(expected) != std::string::npos) {
      if (!found) std::printf("[warning] %s: %s\n", tool.c_str(), line.c_str());
      found = true;
    }
  }
  EXPECT_TRUE(found) << "expected a warning with '" << expected << "' in\n" << what;
}

// Exit code 0, nothing but log lines on stderr, and no warning or error among them.
void ExpectQuiet(const std::string& tool, const std::string& args) {
  const Outcome o = Run(tool, args);
  const std::string what =
      tool + " " + args + "\nexit code " + std::to_string(o.code) + "\nstderr:\n" + o.err;
  EXPECT_EQ(o.code, 0) << what;
  EXPECT_TRUE(Lines(o.err).empty()) << what;
}

void WriteFile(const std::string& path, const std::string& content) {
  fs::remove(path);
  std::ofstream(path, std::ios::binary) << content;
}

std::string Head(const std::string& path, size_t bytes) {
  return io::ReadTextFile(path).substr(0, bytes);
}

// <kBad>/<name>/00: the run's sequence as symbolic links (frames [0, frames)), so that one file
// can be replaced. Its dataset id equals the original's (same folder name, calib and times).
std::string Sequence(const std::string& name, int frames, const std::string& folder = "00") {
  const std::string dir = kBad + "/" + name + "/" + folder;
  fs::remove_all(dir);
  for (const std::string sub : {"velodyne", "image_0"}) {
    fs::create_directories(dir + "/" + sub);
    for (int f = 0; f < frames; ++f) {
      char file[32];
      std::snprintf(file, sizeof(file), "/%06d.%s", f, sub == "velodyne" ? "bin" : "png");
      fs::create_symlink(kSeq + "/" + sub + file, dir + "/" + sub + file);
    }
  }
  fs::copy_file(kSeq + "/calib.txt", dir + "/calib.txt");
  fs::copy_file(kSeq + "/times.txt", dir + "/times.txt");
  return dir;
}

std::string Scan(const std::string& seq, int frame) {
  char file[32];
  std::snprintf(file, sizeof(file), "/velodyne/%06d.bin", frame);
  return seq + file;
}

std::string Image(const std::string& seq, int frame) {
  char file[32];
  std::snprintf(file, sizeof(file), "/image_0/%06d.png", frame);
  return seq + file;
}

io::Provenance WithDataset(const std::string& id) {
  io::Provenance p;
  p.tool = "bad_input_test";
  p.dataset_id = id;
  return p;
}

class BadInputTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!io::FileExists(In("global.h5"))) return;
    fs::remove_all(kBad);
    fs::create_directories(kBad);
    id_ = io::ReadArtifactDatasetId(In("visual.h5"));
    // A small chain (8 keyframes) for the stages whose fallbacks run to the end.
    const std::string q = " --quiet --log-level warn --threads 1";
    const std::string small = kBin + "visual_assoc --dataset " + kSeq + " --frames 0:8 --prior " +
                              In("prior.h5") + " --directions " + In("directions.h5") + " -o " +
                              Bad("visual8.h5") + q + " > /dev/null && " + kBin +
                              "local_map --visual " + Bad("visual8.h5") + " --dataset " + kSeq +
                              " -o " + Bad("local8.h5") + q + " > /dev/null";
    ASSERT_EQ(std::system(small.c_str()), 0) << small;
  }
  void SetUp() override {
    if (!io::FileExists(In("global.h5"))) GTEST_SKIP() << kRun << " incomplete (robust_pipeline_a)";
  }
  static std::string id_;
};
std::string BadInputTest::id_;

TEST_F(BadInputTest, MissingAndDamagedDatasetFiles) {
  for (const std::string tool :
       {"dataset_info", "lidar_odom", "vp_detect", "sensor_stats", "calib_check"}) {
    const std::string out = tool == "dataset_info" ? "" : " -o " + Bad("x.h5");
    ExpectError(tool, "--dataset " + Bad("no_such_folder") + out, "no_such_folder: dataset folder");
  }
  const std::string no_calib = Sequence("no_calib", 4);
  fs::remove(no_calib + "/calib.txt");
  ExpectError("lidar_odom", "--dataset " + no_calib + " -o " + Bad("x.h5"), "no_calib/00: unknown");

  const std::string cut_calib = Sequence("cut_calib", 4);
  WriteFile(cut_calib + "/calib.txt", Head(kSeq + "/calib.txt", 150));
  ExpectError("vp_detect", "--dataset " + cut_calib + " -o " + Bad("x.h5"),
              "calib.txt:1: P0 has 8 numbers, expected 12");
  const std::string full = io::ReadTextFile(kSeq + "/calib.txt");
  WriteFile(cut_calib + "/calib.txt", full.substr(0, full.find("P3:")));
  ExpectError("visual_assoc",
              "--dataset " + cut_calib + " --prior " + In("prior.h5") + " -o " + Bad("x.h5"),
              "calib.txt: missing P3 (3x4 projection matrix)");

  const std::string long_p0 = Sequence("long_p0", 4);
  std::string calib = io::ReadTextFile(kSeq + "/calib.txt");
  calib.replace(calib.find("P0: ") + 4, 0, "7 ");
  WriteFile(long_p0 + "/calib.txt", calib);
  ExpectError("dataset_info", "-d " + long_p0, "calib.txt:1: P0 has 13 numbers, expected 12");

  const std::string nan_calib = Sequence("nan_calib", 4);
  calib = io::ReadTextFile(kSeq + "/calib.txt");
  const size_t first = calib.find("P0: ") + 4;
  calib.replace(first, calib.find(' ', first) - first, "nan");
  WriteFile(nan_calib + "/calib.txt", calib);
  ExpectError("dataset_info", "-d " + nan_calib, "calib.txt:1: bad number 'nan");

  const std::string zero_tr = Sequence("zero_tr", 4);
  calib = io::ReadTextFile(kSeq + "/calib.txt");
  calib = calib.substr(0, calib.find("Tr:")) + "Tr: 0 0 0 0 0 0 0 0 0 0 0 0\n";
  WriteFile(zero_tr + "/calib.txt", calib);
  ExpectError("lidar_odom", "--dataset " + zero_tr + " -o " + Bad("x.h5"),
              "calib.txt: Tr is not a rigid transform");

  const std::string cut_times = Sequence("cut_times", 4);
  WriteFile(cut_times + "/times.txt", Head(kSeq + "/times.txt", 20));
  ExpectError("visual_assoc",
              "--dataset " + cut_times + " --prior " + In("prior.h5") + " -o " + Bad("x.h5"),
              "times.txt: 2 timestamps but the sequence has frame 3");
  const std::string bad_times = Sequence("bad_times", 4);
  WriteFile(bad_times + "/times.txt", "0.0\n0.1\nabc\n0.3\n");
  ExpectError("dataset_info", "-d " + bad_times, "times.txt:3: bad timestamp 'abc'");
}

TEST_F(BadInputTest, DamagedScans) {
  // local_map on the 8-keyframe visual map of kSeq, reading the scans of `dir`.
  const auto local_map_on = [&](const std::string& dir) {
    return "--visual " + Bad("visual8.h5") + " --dataset " + dir + " -o " + Bad("x.h5");
  };
  const std::string odd = Sequence("odd_bin", 40);
  WriteFile(Scan(odd, 3), Head(Scan(kSeq, 3), 16 * 1000 + 7));
  ExpectError("lidar_odom", "--dataset " + odd + " --frames 0:5 -o " + Bad("x.h5"),
              "000003.bin: size 16007 bytes is not a multiple of 16");
  ExpectError("dataset_info", "-d " + odd + " --check-scans", "000003.bin: size 16007");
  ExpectError("local_map", local_map_on(odd), "000003.bin: size 16007");

  const std::string missing = Sequence("missing_bin", 40);
  fs::remove(Scan(missing, 5));
  ExpectError("local_map", local_map_on(missing), "000005.bin: missing scan for frame 5");

  // Non-finite points are dropped with a warning; an empty scan keeps the motion model.
  const std::string nonfinite = Sequence("nonfinite_bin", 40);
  std::string bytes = io::ReadTextFile(Scan(kSeq, 2));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i + 16 <= bytes.size(); i += 16 * 5) std::memcpy(&bytes[i], &nan, 4);
  for (size_t i = 16 * 2; i + 16 <= bytes.size(); i += 16 * 7) std::memcpy(&bytes[i + 8], &inf, 4);
  WriteFile(Scan(nonfinite, 2), bytes);
  ExpectWarning("lidar_odom", "--dataset " + nonfinite + " --frames 0:5 -o " + Bad("x.h5"),
                "000002.bin: dropped");
  ExpectWarning("dataset_info", "-d " + nonfinite + " --check-scans", "non-finite points");
  ExpectWarning("local_map", local_map_on(nonfinite), "000002.bin: dropped");

  const std::string empty = Sequence("empty_bin", 40);
  WriteFile(Scan(empty, 0), "");
  WriteFile(Scan(empty, 3), "");
  ExpectWarning("lidar_odom", "--dataset " + empty + " --frames 0:6 -o " + Bad("x.h5"),
                "000003.bin: empty scan (frame 3)");
  ExpectWarning("local_map", local_map_on(empty), "empty scan");
}

TEST_F(BadInputTest, DamagedImages) {
  const std::string garbage = Sequence("garbage_png", 6);
  WriteFile(Image(garbage, 2), "this is not an image");
  ExpectError("vp_detect", "--dataset " + garbage + " -o " + Bad("x.h5"),
              "000002.png: image does not decode");
  ExpectError("visual_assoc",
              "--dataset " + garbage + " --prior " + In("prior.h5") + " -o " + Bad("x.h5"),
              "000002.png: image does not decode");

  const std::string cut = Sequence("cut_png", 6);
  WriteFile(Image(cut, 4), Head(Image(kSeq, 4), 5000));
  ExpectError("vp_detect", "--dataset " + cut + " -o " + Bad("x.h5"), "000004.png: truncated PNG");
  ExpectError("visual_assoc",
              "--dataset " + cut + " --prior " + In("prior.h5") + " -o " + Bad("x.h5"),
              "000004.png: truncated PNG");

  const std::string missing = Sequence("missing_png", 6);
  fs::remove(Image(missing, 1));
  ExpectError("vp_detect", "--dataset " + missing + " -o " + Bad("x.h5"),
              "000001.png: missing image of camera 0 for frame 1");

  const std::string first_bad = Sequence("first_png", 3);
  WriteFile(Image(first_bad, 0), "");
  ExpectError("dataset_info", "-d " + first_bad, "000000.png: empty image file");
}

// --camera: a camera number out of range, a camera without images (run_a has camera 0 only),
// and artifacts of two cameras mixed (run_cam2's visual map with run_a's camera-0 directions).
TEST_F(BadInputTest, CameraChoice) {
  ExpectError("vp_detect", "--dataset " + kSeq + " --camera 9 -o " + Bad("x.h5"),
              "--camera 9 is not a camera (0..3)");
  ExpectError("vp_detect", "--dataset " + kSeq + " --camera 2 -o " + Bad("x.h5"),
              "image_2/000000.png: missing image of camera 2 for frame 0");
  ExpectError("visual_assoc",
              "--dataset " + kSeq + " --camera 2 --prior " + In("prior.h5") + " -o " + Bad("x.h5"),
              "missing image of camera 2 for frame 0");
  const std::string cam2 = std::string(JVL_BINARY_DIR) + "/tests/robustness/run_cam2/";
  if (!io::FileExists(cam2 + "global.h5")) GTEST_SKIP() << cam2 << " incomplete";
  ExpectError("global_opt",
              "--local " + cam2 + "local.h5 --visual " + cam2 + "visual.h5 --directions " +
                  In("directions.h5") + " -o " + Bad("x.h5"),
              "its vanishing points are pixels of camera 0, but " + cam2 +
                  "visual.h5 was built from camera 2");
}

TEST_F(BadInputTest, TruncatedAndWrongArtifacts) {
  for (const std::string a : {"prior.h5", "vps.h5", "directions.h5", "visual.h5", "local.h5"}) {
    WriteFile(Bad("cut_" + a), Head(In(a), io::FileSize(In(a)) / 2));
    WriteFile(Bad("empty_" + a), "");
  }
  const std::string dirs = " --directions " + In("directions.h5");
  ExpectError("direction_cluster",
              "--vps " + Bad("cut_vps.h5") + " --prior " + In("prior.h5") + " -o " + Bad("x.h5"),
              "cut_vps.h5: cannot open HDF5 file");
  ExpectError("direction_cluster",
              "--vps " + In("vps.h5") + " --prior " + Bad("empty_prior.h5") + " -o " + Bad("x.h5"),
              "empty_prior.h5: not an HDF5 file");
  ExpectError("visual_assoc",
              "--dataset " + kSeq + " --prior " + Bad("cut_prior.h5") + " -o " + Bad("x.h5"),
              "cut_prior.h5: cannot open HDF5 file");
  ExpectError("visual_assoc",
              "--dataset " + kSeq + " --prior " + In("prior.h5") + " --directions " +
                  Bad("cut_directions.h5") + " -o " + Bad("x.h5"),
              "cut_directions.h5");
  ExpectError("local_map",
              "--visual " + Bad("cut_visual.h5") + " --dataset " + kSeq + " -o " + Bad("x.h5"),
              "cut_visual.h5: cannot open HDF5 file");
  ExpectError("global_opt",
              "--local " + Bad("cut_local.h5") + " --visual " + In("visual.h5") + dirs + " -o " +
                  Bad("x.h5"),
              "cut_local.h5: cannot open");
  ExpectError("global_opt",
              "--local " + In("local.h5") + " --visual " + Bad("empty_visual.h5") + dirs + " -o " +
                  Bad("x.h5"),
              "empty_visual.h5: not an HDF5 file");
  ExpectError("global_opt",
              "--local " + In("local.h5") + " --visual " + In("visual.h5") + dirs +
                  " --motion-sigma 4 0 9 -o " + Bad("x.h5"),
              "--motion-sigma: '0' is not a sigma > 0 in mm");
  ExpectError("global_opt",
              "--local " + In("local.h5") + " --visual " + In("visual.h5") + dirs +
                  " --surface-sigma 0 -o " + Bad("x.h5"),
              "--surface-sigma must be positive");
  ExpectError("global_opt",
              "--local " + In("local.h5") + " --visual " + In("visual.h5") + dirs +
                  " --odometry-max-inflation 0.5 -o " + Bad("x.h5"),
              "--odometry-max-inflation must be >= 1");
  ExpectError("evaluate", "--gt " + kRun + "/data/poses/00.txt --est " + Bad("cut_prior.h5"),
              "cut_prior.h5: cannot open HDF5 file");
  ExpectError("make_prior", "-g " + Bad("empty_prior.h5") + " -o " + Bad("x.h5"),
              "empty_prior.h5: not an HDF5 file");

  // Wrong schema name and wrong schema version.
  ExpectError("local_map", "--visual " + In("vps.h5") + " --dataset " + kSeq + " -o " + Bad("x.h5"),
              "vps.h5: expected schema 'visual' version 1, found 'vps' version 1");
  ExpectError(
      "global_opt",
      "--local " + In("visual.h5") + " --visual " + In("visual.h5") + dirs + " -o " + Bad("x.h5"),
      "expected schema 'local' version 1, found 'visual'");
  ExpectError("direction_cluster",
              "--vps " + In("directions.h5") + " --prior " + In("prior.h5") + " -o " + Bad("x.h5"),
              "expected schema 'vps'");
  ExpectError("evaluate", "--gt " + In("vps.h5") + " --est " + In("prior.h5"),
              "vps.h5: artifact 'vps' holds no trajectory");
  {
    io::H5Writer w(Bad("visual_v2.h5"), "visual", 2);
    w.Commit(WithDataset(id_));
  }
  ExpectError("local_map",
              "--visual " + Bad("visual_v2.h5") + " --dataset " + kSeq + " -o " + Bad("x.h5"),
              "expected schema 'visual' version 1, found 'visual' version 2");
  ExpectError("global_opt",
              "--local " + In("local.h5") + " --visual " + Bad("visual_v2.h5") + dirs + " -o " +
                  Bad("x.h5"),
              "found 'visual' version 2");
}

TEST_F(BadInputTest, DamagedTrajectoryText) {
  const std::string gt = kRun + "/data/poses/00.txt";
  const std::string text = io::ReadTextFile(gt);
  // Cut after the fourth number of the line in the middle of the file.
  const size_t start = text.rfind('\n', text.size() / 2) + 1;
  std::istringstream middle(text.substr(start, text.find('\n', start) - start));
  std::string cut = text.substr(0, start), token;
  for (int k = 0; k < 4 && middle >> token; ++k) cut += (k > 0 ? " " : "") + token;
  const auto cut_line = std::count(text.begin(), text.begin() + static_cast<long>(start), '\n') + 1;
  WriteFile(Bad("cut.txt"), cut);
  WriteFile(Bad("nan.txt"), "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 nan 0 1 0 0 0 0 1 0\n");
  WriteFile(Bad("empty.txt"), "");
  WriteFile(Bad("scaled.txt"), "2 0 0 0 0 2 0 0 0 0 2 0\n");
  WriteFile(Bad("tum_q.txt"), "0.0 0 0 0 0 0 0 2\n");
  WriteFile(Bad("back.txt"), "5 1 0 0 0 0 1 0 0 0 0 1 0\n3 1 0 0 0 0 1 0 0 0 0 1 0\n");
  ExpectError("make_prior", "-g " + Bad("cut.txt") + " -o " + Bad("x.h5"),
              "cut.txt:" + std::to_string(cut_line) + ": 4 columns");
  ExpectError("make_prior", "-g " + Bad("nan.txt") + " -o " + Bad("x.h5"),
              "nan.txt:2: bad number 'nan' in column 4");
  ExpectError("evaluate", "--gt " + gt + " --est " + Bad("empty.txt"), "empty.txt: no poses found");
  ExpectError("evaluate", "--gt " + Bad("scaled.txt") + " --est " + gt,
              "scaled.txt:1: rotation part is not a rotation");
  ExpectError("direction_cluster",
              "--vps " + In("vps.h5") + " --prior " + Bad("tum_q.txt") + " -o " + Bad("x.h5"),
              "tum_q.txt:1: quaternion is not unit");
  ExpectError("visual_assoc",
              "--dataset " + kSeq + " --prior " + Bad("back.txt") + " -o " + Bad("x.h5"),
              "back.txt:2: frame 3 does not increase");
  ExpectError("evaluate", "--gt " + gt + " --est " + Bad("missing.txt"),
              "missing.txt: file not found");
}

TEST_F(BadInputTest, ArtifactsOfDifferentSequences) {
  const std::string other_id = "kitti:01:0123abcd";
  io::WriteVisualMap(Bad("visual_01.h5"), io::ReadVisualMap(In("visual.h5")),
                     WithDataset(other_id));
  io::WriteVpsArtifact(Bad("vps_01.h5"), io::ReadVpsArtifact(In("vps.h5")), WithDataset(other_id));
  io::WriteDirectionsArtifact(Bad("directions_01.h5"),
                              io::ReadDirectionsArtifact(In("directions.h5")),
                              WithDataset(other_id));
  ExpectError("global_opt",
              "--local " + In("local.h5") + " --visual " + Bad("visual_01.h5") + " --directions " +
                  In("directions.h5") + " -o " + Bad("x.h5"),
              "(inputs of different sequences)");
  ExpectError("global_opt",
              "--local " + In("local.h5") + " --visual " + In("visual.h5") + " --directions " +
                  Bad("directions_01.h5") + " -o " + Bad("x.h5"),
              "directions_01.h5 was made from sequence 'kitti:01:0123abcd'");
  ExpectError("direction_cluster",
              "--vps " + Bad("vps_01.h5") + " --prior " + In("odom.h5") + " -o " + Bad("x.h5"),
              "odom.h5 was made from sequence");
  ExpectError("visual_assoc",
              "--dataset " + kSeq + " --prior " + In("prior.h5") + " --directions " +
                  Bad("directions_01.h5") + " -o " + Bad("x.h5"),
              "directions_01.h5 was made from sequence 'kitti:01:0123abcd'");
  ExpectError(
      "sensor_stats",
      "-d " + kSeq + " --no-scans --no-images --vps " + Bad("vps_01.h5") + " -o " + Bad("s.json"),
      "vps_01.h5 was made from sequence 'kitti:01:0123abcd'");
  // The same frames under another sequence name: local_map must not take them for run_a's.
  const std::string renamed = Sequence("renamed", 40, "01");
  ExpectError("local_map",
              "--visual " + In("visual.h5") + " --dataset " + renamed + " -o " + Bad("x.h5"),
              "(inputs of different sequences)");
}

TEST_F(BadInputTest, FrameRangesThatDoNotOverlap) {
  ExpectError("dataset_info", "-d " + kSeq + " --frames 100:200",
              "--frames 100:200 selects no frame of");
  ExpectError("vp_detect", "--dataset " + kSeq + " --frames 50: -o " + Bad("x.h5"),
              "--frames 50: selects no frame");
  // A prior of frames 0-9 for frames 20-39.
  Trajectory prior = io::ReadTrajectory(In("prior.h5"));
  Trajectory first10;
  for (size_t i = 0; i < 10; ++i) first10.Append(prior.frames[i], prior.world_from_cam[i]);
  io::WriteTrajectoryKitti(Bad("prior_0_9.txt"), first10);
  ExpectError("visual_assoc",
              "--dataset " + kSeq + " --frames 20:40 --prior " + Bad("prior_0_9.txt") + " -o " +
                  Bad("x.h5"),
              "prior_0_9.txt");
  ExpectError("local_map",
              "--visual " + In("visual.h5") + " --dataset " + kSeq + " --prior " +
                  Bad("prior_0_9.txt") + " -o " + Bad("x.h5"),
              "prior_0_9.txt");
  // Estimate and ground truth without a common frame.
  Trajectory late;
  for (size_t i = 20; i < prior.size(); ++i) late.Append(prior.frames[i], prior.world_from_cam[i]);
  io::WriteTrajectoryKitti(Bad("prior_20_39.txt"), late);
  ExpectError("evaluate", "--gt " + Bad("prior_0_9.txt") + " --est " + Bad("prior_20_39.txt"),
              "prior_20_39.txt");
  // VPs of frames the prior lacks are skipped with a warning.
  ExpectWarning("direction_cluster",
                "--vps " + In("vps.h5") + " --prior " + Bad("prior_0_9.txt") + " -o " + Bad("x.h5"),
                "VPs skipped");
}

TEST_F(BadInputTest, EmptyContent) {
  // Zero VPs: no direction priors, with a warning; downstream runs without them.
  io::VpsData vps = io::ReadVpsArtifact(In("vps.h5"));
  vps.vps.clear();
  io::WriteVpsArtifact(Bad("vps_none.h5"), vps, WithDataset(id_));
  ExpectWarning("direction_cluster",
                "--vps " + Bad("vps_none.h5") + " --prior " + In("prior.h5") + " -o " +
                    Bad("directions_none.h5"),
                "no direction prior", {Bad("directions_none.h5")});
  ExpectWarning("global_opt",
                "--local " + Bad("local8.h5") + " --visual " + Bad("visual8.h5") +
                    " --directions " + Bad("directions_none.h5") + " -o " + Bad("x.h5"),
                "no direction prior");
  // No keyframes.
  io::VisualMapData visual = io::ReadVisualMap(Bad("visual8.h5"));
  io::VisualMapData none = visual;
  none.keyframes = Trajectory();
  none.keypoint_keyframe.clear();
  none.keypoint_uv.clear();
  none.keypoint_octave.clear();
  none.keypoint_angle.clear();
  none.keypoint_descriptor.clear();
  none.mappoint_position.clear();
  none.mappoint_descriptor.clear();
  none.mappoint_normal.clear();
  none.observation_keyframe.clear();
  none.observation_keypoint.clear();
  none.observation_mappoint.clear();
  none.covisibility_edges.clear();
  none.covisibility_weight.clear();
  io::WriteVisualMap(Bad("visual_none.h5"), none, WithDataset(id_));
  ExpectError("local_map",
              "--visual " + Bad("visual_none.h5") + " --dataset " + kSeq + " -o " + Bad("x.h5"),
              "visual_none.h5: no keyframes");
  ExpectError("global_opt",
              "--local " + Bad("local8.h5") + " --visual " + Bad("visual_none.h5") +
                  " --directions " + In("directions.h5") + " -o " + Bad("x.h5"),
              "visual_none.h5: no keyframes");
  ExpectError("global_opt",
              "--local " + In("local.h5") + " --visual " + Bad("visual8.h5") + " --directions " +
                  In("directions.h5") + " -o " + Bad("x.h5"),
              "visual8.h5 have different keyframes (40 vs 8)");
  // A covisibility graph in two parts (keyframes 0-3 and 4-7 share no edge).
  io::VisualMapData split = visual;
  split.covisibility_edges.clear();
  split.covisibility_weight.clear();
  for (size_t e = 0; e < visual.num_edges(); ++e) {
    const int32_t a = visual.covisibility_edges[2 * e], b = visual.covisibility_edges[2 * e + 1];
    if ((a < 4) != (b < 4)) continue;
    split.covisibility_edges.insert(split.covisibility_edges.end(), {a, b});
    split.covisibility_weight.push_back(visual.covisibility_weight[e]);
  }
  io::WriteVisualMap(Bad("visual_split.h5"), split, WithDataset(id_));
  ExpectWarning(
      "local_map",
      "--visual " + Bad("visual_split.h5") + " --dataset " + kSeq + " -o " + Bad("local_split.h5"),
      "covisibility graph", {Bad("local_split.h5")});
  ExpectWarning("global_opt",
                "--local " + Bad("local8.h5") + " --visual " + Bad("visual_split.h5") +
                    " --directions " + In("directions.h5") + " -o " + Bad("x.h5"),
                "covisibility graph");
}

TEST_F(BadInputTest, InvalidOptions) {
  const std::string seq = " --dataset " + kSeq + " -o " + Bad("x.h5");
  ExpectError("dataset_info", "-d " + kSeq + " --threads -2", "--threads must be >= 0");
  ExpectError("dataset_info", "-d " + kSeq + " --frames 9:3", "--frames: end must be");
  ExpectError("dataset_info", "-d " + kSeq + " --format kitti-odometry", "--format: unknown");
  ExpectError("dataset_info", "-d " + kSeq + " --no-such-option", "--no-such-option");
  ExpectError("sensor_stats", "-d " + kSeq + " -o " + Bad("s.json") + " --every 0", "--every");
  ExpectError("sensor_stats", "-d " + kSeq + " -o " + Bad("s.json") + " --no-scans --no-images",
              "--no-scans and --no-images leave nothing");
  ExpectError("sensor_stats", "-d " + kSeq + " -o " + Bad("s.json") + " --shape-radius 0",
              "voxel_size and radius must be > 0");
  ExpectError("sensor_stats",
              "-d " + kSeq + " -o " + Bad("s.json") + " --no-scans --no-images --odometry " +
                  In("odom.h5") + " --drift-length 0",
              "--drift-length must be > 0");
  ExpectError(
      "sensor_stats",
      "-d " + kSeq + " -o " + Bad("s.json") + " --no-scans --no-images --visual " + In("vps.h5"),
      "expected schema 'visual'");
  const std::string calib = "-d " + kSeq + " -o " + Bad("c.json");
  ExpectError("calib_check", calib + " --min-depth 90",
              "--min-depth must be > 0 and < --max-depth");
  ExpectError("calib_check", calib + " --fine-step 0.5",
              "--fine-step must be > 0 and <= --coarse-step");
  ExpectError("calib_check", calib + " --search 20", "--search must be within");
  ExpectError("calib_check", calib + " --vertical-correction 30", "--vertical-correction must be");
  ExpectError("calib_check", calib + " --camera 3", "missing image of camera 3");
  ExpectError("calib_check", calib + " --min-depth 70 --max-depth 71",
              "too few to measure the calibration by");
  const std::string loops = "-d " + kSeq + " --poses " + In("odom.h5") + " -o " + Bad("l.h5");
  ExpectError("loop_detect", loops + " --every 0", "--every");
  ExpectError("loop_detect", loops + " --vertical-correction 9", "--vertical-correction must be");
  ExpectError("loop_detect", loops + " --max-descriptor-distance 0",
              "--max-descriptor-distance must be in (0, 1]");
  ExpectError("loop_detect", loops + " --consistency 0", "--consistency must be >= 1");
  ExpectError("loop_detect", loops + " --visual-consistency 0",
              "--visual-consistency must be >= 1");
  ExpectError("loop_detect", loops + " --min-inliers 2", "--min-inliers must be >= 4");
  ExpectError("loop_detect", loops + " --visual-features 0", "--visual-features must be > 0");
  ExpectError("loop_detect", loops + " --detectors lidar,radar", "--detectors");
  ExpectError("loop_detect", loops + " --proximity-radius 0",
              "--proximity-radius must be > 0 and --proximity-drift >= 0");
  ExpectError("loop_detect", loops + " --vocabulary " + Bad("no_vocabulary.h5"),
              "no_vocabulary.h5 not found: give one with --vocabulary");
  ExpectError("loop_detect", loops + " --vocabulary " + In("odom.h5"), "odom.h5");
  ExpectError("loop_detect", loops + " --visual " + In("odom.h5"),
              "odom.h5: expected schema 'visual'");
  ExpectError("loop_detect", "-d " + kSeq + " --poses " + Bad("none.h5") + " -o " + Bad("l.h5"),
              "none.h5");
  ExpectError("sim_sequence", "-o " + Bad("sim") + " --sequence 1x",
              "--sequence must be two digits");
  ExpectError("sim_sequence", "-o " + Bad("sim") + " --frames 100000", "--frames 100000 exceeds");
  ExpectError("sim_sequence", "-o " + Bad("sim") + " --scenario mars", "mars");
  ExpectError("sim_sequence", "-o " + Bad("sim") + " --calib-error-deg -1",
              "--calib-error-deg must be in [0, 10] deg");
  ExpectError("sim_sequence", "-o " + Bad("sim") + " --lidar-elevation-bias 5",
              "--lidar-elevation-bias must be in [-2, 2] deg");
  ExpectError("make_prior", "-g " + In("prior.h5") + " -o " + Bad("x.h5") + " --preset bogus",
              "unknown prior preset 'bogus'");
  ExpectError("make_prior", "-g " + In("prior.h5") + " -o " + Bad("x.h5") + " --yaw-drift nan",
              "--yaw-drift");
  ExpectError("make_prior", "-g " + In("prior.h5") + " -o " + Bad("x.h5") + " --scale-bias 0.7",
              "--scale-bias");
  ExpectError("lidar_odom", seq + " --voxel-size -1", "voxel");
  ExpectError("lidar_odom", seq + " --scan-map-size 0", "scan");
  ExpectError("lidar_odom", seq + " --log-level loud", "--log-level: unknown level 'loud'");
  ExpectError("lidar_odom", seq + " --vertical-correction on",
              "--vertical-correction: expected auto or an angle in degrees, got 'on'");
  ExpectError("lidar_odom", seq + " --vertical-correction 30", "--vertical-correction must be");
  ExpectError("vp_detect", seq + " --canny-low 0", "--canny-low");
  ExpectError("vp_detect", seq + " --detector hough", "hough");
  ExpectError("vp_detect", seq + " --line-scale 0", "--line-scale must be in (0.05, 1]");
  ExpectError(
      "direction_cluster",
      "--vps " + In("vps.h5") + " --prior " + In("prior.h5") + " -o " + Bad("x.h5") + " --up 0,0,0",
      "--up");
  ExpectError(
      "direction_cluster",
      "--vps " + In("vps.h5") + " --prior " + In("prior.h5") + " -o " + Bad("x.h5") + " --th-f 0",
      "Th_f");
  ExpectError("visual_assoc", seq + " --prior " + In("prior.h5") + " --orb-features 0", "orb");
  ExpectError("local_map", "--visual " + In("visual.h5") + seq + " --alpha 0", "alpha");
  ExpectError("local_map", "--visual " + In("visual.h5") + seq + " --vertical-correction x",
              "--vertical-correction: expected auto or an angle in degrees, got 'x'");
  ExpectError("local_map", "--visual " + In("visual.h5") + seq + " --samples-per-list 0",
              "--samples-per-list");
  const std::string global =
      "--local " + In("local.h5") + " --visual " + In("visual.h5") + " -o " + Bad("x.h5");
  ExpectError("global_opt", global, "--directions is required");
  ExpectError("global_opt", global + " --no-direction --map-voxel 0.0001", "--map-voxel");
  ExpectError("global_opt", global + " --no-direction --alpha nan", "alpha");
  ExpectError("evaluate", "--gt " + In("prior.h5") + " --est " + In("odom.h5") + " --align best",
              "best");
  ExpectError("evaluate", "--gt " + In("prior.h5") + " --est " + In("odom.h5") + " --rpe-delta 0",
              "--rpe-delta");
  // An output that cannot be written: the message names it.
  ExpectError("make_prior", "-g " + In("prior.h5") + " -o " + kBad, "bad: is a folder");
}

// ---------------------------------------------------------------------------------------------
// An output that is one of the inputs (by path, "./", symbolic link or hard link, or a file of
// the dataset) is refused before any work, naming both; two outputs on one path likewise.

void CopyTo(const std::string& from, const std::string& to) {
  fs::remove(to);
  fs::copy_file(from, to);
}

TEST_F(BadInputTest, OutputThatIsAnInputIsRefused) {
  const std::string seq = Sequence("out_in", 8);
  const std::string same = "is the same file as input";
  for (const std::string a : {"prior.h5", "vps.h5", "directions.h5", "visual.h5", "local.h5"})
    CopyTo(In(a), Bad("own_" + a));
  CopyTo(kRun + "/data/poses/00.txt", Bad("own_gt.txt"));
  CopyTo(In("odom.txt"), Bad("own_odom.txt"));
  const std::string vps = Bad("own_vps.h5"), prior = Bad("own_prior.h5");
  const std::string dirs = Bad("own_directions.h5"), visual = Bad("own_visual.h5");
  const std::string local = Bad("own_local.h5"), gt = Bad("own_gt.txt");
  fs::remove(Bad("vps_hardlink.h5"));
  fs::create_hard_link(vps, Bad("vps_hardlink.h5"));
  fs::remove(Bad("prior_symlink.h5"));
  fs::create_symlink(prior, Bad("prior_symlink.h5"));

  ExpectError("lidar_odom", "--dataset " + seq + " -o " + seq + "/calib.txt",
              "output --output " + seq + "/calib.txt is the same file as input");
  ExpectError("lidar_odom",
              "--dataset " + seq + " -o " + Bad("x.h5") + " --kitti-poses " + Bad("./x.h5"),
              "are the same file");
  ExpectError("vp_detect",
              "--dataset " + seq + " -o " + Bad("x.h5") + " --csv " + seq + "/times.txt", same);
  // A symbolic link into run_a's images: the image itself must stay.
  ExpectError("vp_detect", "--dataset " + seq + " -o " + Image(seq, 2), same);
  ExpectError("direction_cluster",
              "--vps " + vps + " --prior " + prior + " -o " + Bad("vps_hardlink.h5"), same);
  ExpectError("direction_cluster",
              "--vps " + vps + " --prior " + gt + " -o " + Bad("x.h5") + " --csv " + gt, same);
  ExpectError("direction_cluster",
              "--vps " + vps + " --prior " + prior + " -o " + Bad("x.h5") + " --plot " +
                  Bad("prior_symlink.h5"),
              same);
  ExpectError("visual_assoc",
              "--dataset " + seq + " --prior " + prior + " -o " + kBad + "/./own_prior.h5", same);
  ExpectError("visual_assoc", "--dataset " + seq + " --prior " + prior + " -o " + Scan(seq, 3),
              same);
  ExpectError("local_map",
              "--visual " + visual + " --dataset " + seq + " -o " + Bad("x.h5") +
                  " --kitti-poses " + Scan(seq, 3),
              same);
  const std::string global = "--local " + local + " --visual " + visual + " --directions " + dirs;
  ExpectError("global_opt", global + " -o " + local, same);
  ExpectError("global_opt", global + " -o " + Bad("x.h5") + " --map " + visual, same);
  ExpectError("global_opt", global + " -o " + Bad("x.h5") + " --kitti-poses " + dirs, same);
  ExpectError("global_opt", global + " -o " + Bad("x.h5") + " --map " + Bad("x.h5"),
              "are the same file");
  ExpectError("make_prior", "-g " + gt + " -o " + gt, same);
  ExpectError("evaluate", "--gt " + gt + " --est " + prior + " --json " + gt, same);
  ExpectError("evaluate",
              "--gt " + gt + " --est " + Bad("own_odom.txt") + " --markdown " + Bad("own_odom.txt"),
              same);
  ExpectError("sim_map_check", "--sequence " + kSeq + " --visual " + visual + " --json " + visual,
              same);
  ExpectError("sim_map_check",
              "--sequence " + kSeq + " --visual " + visual + " --points-csv " + kSeq + "/calib.txt",
              same);
}

// ---------------------------------------------------------------------------------------------
// Inputs that were once read silently wrong.

// Sets element `index` of a float64 dataset of an HDF5 file in place.
void PatchDouble(const std::string& path, const std::string& dataset, size_t index, double value) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(file, 0) << path;
  const hid_t d = H5Dopen2(file, dataset.c_str(), H5P_DEFAULT);
  ASSERT_GE(d, 0) << path << ":" << dataset;
  const hid_t space = H5Dget_space(d);
  std::vector<double> v(static_cast<size_t>(H5Sget_simple_extent_npoints(space)));
  ASSERT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0);
  ASSERT_LT(index, v.size());
  v[index] = value;
  ASSERT_GE(H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0);
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(file);
}

TEST_F(BadInputTest, ConfigFileWithAnUnknownKey) {
  WriteFile(Bad("typo.ini"), "no-such-key = 3\n");
  ExpectError("lidar_odom",
              "--dataset " + kSeq + " -o " + Bad("x.h5") + " --config " + Bad("typo.ini"),
              "typo.ini: INI was not able to parse no-such-key");
  ExpectError("evaluate",
              "--gt " + In("prior.h5") + " --est " + In("odom.h5") + " --config " + Bad("typo.ini"),
              "typo.ini: INI was not able to parse");
}

TEST_F(BadInputTest, TimesAndFrameRanges) {
  const std::string back = Sequence("times_back", 4);
  WriteFile(back + "/times.txt", "0.0\n0.2\n0.1\n0.3\n");
  ExpectError("dataset_info", "-d " + back, "times.txt:3: timestamp 0.1 does not increase");
  ExpectError("lidar_odom", "--dataset " + back + " -o " + Bad("x.h5"), "does not increase");
  for (const std::string tool : {"lidar_odom", "vp_detect"}) {
    ExpectError(tool, "--dataset " + kSeq + " --frames 0:9999 -o " + Bad("x.h5"),
                "--frames 0:9999 goes past the last frame");
    ExpectError(tool, "--dataset " + kSeq + " --frames 30:20 -o " + Bad("x.h5"),
                "--frames: end must be an integer > start");
  }
  ExpectError(
      "visual_assoc",
      "--dataset " + kSeq + " --frames 0:9999 --prior " + In("prior.h5") + " -o " + Bad("x.h5"),
      "goes past the last frame");
  ExpectError("dataset_info", "-d " + kSeq + " --frames 10:41", "goes past the last frame");
}

TEST_F(BadInputTest, TrajectoryArtifactsAndTumText) {
  {
    io::H5Writer w(Bad("traj_v2.h5"), "trajectory", 2);
    io::WriteTrajectoryGroup(w, "trajectory", io::ReadTrajectory(In("prior.h5")));
    w.Commit(WithDataset(id_));
  }
  ExpectError("evaluate", "--gt " + kRun + "/data/poses/00.txt --est " + Bad("traj_v2.h5"),
              "traj_v2.h5: expected schema 'trajectory' version 1, found 'trajectory' version 2");
  ExpectError("visual_assoc",
              "--dataset " + kSeq + " --prior " + Bad("traj_v2.h5") + " -o " + Bad("x.h5"),
              "found 'trajectory' version 2");
  // Poses are [qx qy qz qw tx ty tz]: qx of frame 3.
  CopyTo(In("prior.h5"), Bad("prior_q.h5"));
  PatchDouble(Bad("prior_q.h5"), "trajectory/poses", 7 * 3, 0.6);
  ExpectError("make_prior", "-g " + Bad("prior_q.h5") + " -o " + Bad("x.h5"),
              "prior_q.h5: trajectory frame 3: quaternion is not unit");
  ExpectError("direction_cluster",
              "--vps " + In("vps.h5") + " --prior " + Bad("prior_q.h5") + " -o " + Bad("x.h5"),
              "quaternion is not unit");
  // Off by text rounding (1e-4 here): normalised, with one warning for the file.
  CopyTo(In("prior.h5"), Bad("prior_q4.h5"));
  {
    Trajectory t = io::ReadTrajectory(In("prior.h5"));
    const auto a = t.world_from_cam[3].ToArray();
    PatchDouble(Bad("prior_q4.h5"), "trajectory/poses", 7 * 3 + 3, a[3] * (1 + 1e-4));
  }
  ExpectWarning("make_prior", "-g " + Bad("prior_q4.h5") + " -o " + Bad("x.h5"),
                "1 rotation(s) not unit");
  WriteFile(Bad("tum_back.txt"), "0.0 0 0 0 0 0 0 1\n0.2 0 0 1 0 0 0 1\n0.1 0 0 2 0 0 0 1\n");
  ExpectError("visual_assoc",
              "--dataset " + kSeq + " --prior " + Bad("tum_back.txt") + " -o " + Bad("x.h5"),
              "tum_back.txt:3: timestamp 0.1 does not increase");
}

TEST_F(BadInputTest, ScansThatAreMissingEmptyOrAbsurd) {
  const std::string gap = Sequence("gap_bin", 8);
  fs::remove(Scan(gap, 3));
  ExpectError("lidar_odom", "--dataset " + gap + " -o " + Bad("x.h5"),
              "000003.bin: missing scan for frame 3");
  fs::remove_all(gap + "/image_0");  // a LiDAR-only sequence: the rule is the same
  ExpectError("lidar_odom", "--dataset " + gap + " -o " + Bad("x.h5"),
              "000003.bin: missing scan for frame 3");

  const std::string folder = Sequence("folder_bin", 8);
  fs::remove(Scan(folder, 2));
  fs::create_directory(Scan(folder, 2));
  ExpectError("lidar_odom", "--dataset " + folder + " -o " + Bad("x.h5"),
              "000002.bin: is a folder, not a scan file");

  // local_map on the 8-keyframe visual map, reading the scans of `dir`.
  const auto local_map_on = [&](const std::string& dir) {
    return "--visual " + Bad("visual8.h5") + " --dataset " + dir + " -o " + Bad("x.h5");
  };
  const std::string zeros = Sequence("zero_bin", 40);
  WriteFile(Scan(zeros, 2), std::string(16 * 1000, '\0'));
  ExpectWarning("local_map", local_map_on(zeros), "only 0 of 1000 points have a surface normal");
  const std::string tiny = Sequence("tiny_bin", 40);
  WriteFile(Scan(tiny, 2), Head(Scan(kSeq, 2), 16 * 10));
  ExpectWarning("local_map", local_map_on(tiny), "of 10 points have a surface normal");

  // Points at 1e30 m: dropped with a count; no library text on the terminal.
  const std::string far = Sequence("far_bin", 40);
  std::string bytes = io::ReadTextFile(Scan(kSeq, 2));
  const float huge = 1e30f;
  size_t count = 0;
  for (size_t i = 0; i + 16 <= bytes.size(); i += 16 * 3, ++count)
    for (int k = 0; k < 3; ++k) std::memcpy(&bytes[i + 4 * k], &huge, 4);
  WriteFile(Scan(far, 2), bytes);
  ExpectWarning("lidar_odom", "--dataset " + far + " --frames 0:5 -o " + Bad("x.h5"),
                "000002.bin: dropped " + std::to_string(count) + " points farther than 1000 m");
  ExpectWarning("local_map", local_map_on(far), "points farther than 1000 m");
}

TEST_F(BadInputTest, ImagesOfAnotherSize) {
  const cv::Mat image = io::ReadImage(Image(kSeq, 3), true);
  cv::Mat smaller;
  cv::resize(image, smaller, cv::Size(image.cols / 2, image.rows / 2));
  // One thread: the images are read in order, so the first bad one is the one named.
  const std::string visual = " --prior " + In("prior.h5") + " -o " + Bad("x.h5") + " --threads 1";
  const std::string third = Sequence("size_3", 6);
  fs::remove(Image(third, 3));
  io::WriteImage(Image(third, 3), smaller);
  ExpectError("visual_assoc", "--dataset " + third + visual,
              "000003.png: image is " + std::to_string(smaller.cols) + "x" +
                  std::to_string(smaller.rows) + " but the sequence's are " +
                  std::to_string(image.cols) + "x" + std::to_string(image.rows));
  ExpectError("vp_detect", "--dataset " + third + " -o " + Bad("x.h5") + " --threads 1",
              "000003.png: image is");
  const std::string first = Sequence("size_0", 6);
  fs::remove(Image(first, 0));
  io::WriteImage(Image(first, 0), smaller);
  ExpectError("visual_assoc", "--dataset " + first + visual,
              "000001.png: image is " + std::to_string(image.cols) + "x" +
                  std::to_string(image.rows) + " but the sequence's are");
  const std::string dot = Sequence("size_1x1", 6);
  fs::remove(Image(dot, 0));
  io::WriteImage(Image(dot, 0), cv::Mat(1, 1, CV_8UC1, cv::Scalar(7)));
  ExpectError("visual_assoc", "--dataset " + dot + visual, "000000.png: image is 1x1, too small");
}

TEST_F(BadInputTest, ArtifactContentAndOptions) {
  CopyTo(In("visual.h5"), Bad("visual_nan.h5"));
  PatchDouble(Bad("visual_nan.h5"), "mappoints/position", 3 * 5 + 1,
              std::numeric_limits<double>::quiet_NaN());
  ExpectError("global_opt",
              "--local " + In("local.h5") + " --visual " + Bad("visual_nan.h5") + " --directions " +
                  In("directions.h5") + " -o " + Bad("x.h5"),
              "visual_nan.h5: map point 5 has a non-finite position");
  ExpectError("local_map",
              "--visual " + Bad("visual_nan.h5") + " --dataset " + kSeq + " -o " + Bad("x.h5"),
              "map point 5 has a non-finite position");
  // --dataset of another sequence than the VPs'.
  const std::string other = Sequence("other_seq", 8, "07");
  ExpectError("direction_cluster",
              "--vps " + In("vps.h5") + " --prior " + In("prior.h5") + " --dataset " + other +
                  " -o " + Bad("x.h5"),
              "(inputs of different sequences)");
  ExpectError("vp_detect", "--dataset " + kSeq + " -o " + Bad("x.h5") + " --seed -1", "--seed");
  ExpectError("make_prior", "-g " + In("prior.h5") + " -o " + Bad("x.h5") + " --seed -3", "--seed");
  // A broken scene description: the message is ours, not the JSON library's.
  const std::string scene = Sequence("scene_json", 40);
  fs::create_directories(scene + "/sim");
  WriteFile(scene + "/sim/scene.json", "{\"schema\": \"sim_scene\", ");
  ExpectError("sim_map_check", "--sequence " + scene + " --visual " + In("visual.h5"),
              "scene.json: not valid JSON (truncated?): parse error at line 1");
  const Outcome o =
      jvl::Run("sim_map_check", "--sequence " + scene + " --visual " + In("visual.h5"));
  EXPECT_EQ(o.err.find("json.exception"), std::string::npos) << o.err;
  // More threads than the machine has: capped with one warning, no solver library text.
  ExpectWarning("global_opt",
                "--local " + Bad("local8.h5") + " --visual " + Bad("visual8.h5") +
                    " --directions " + In("directions.h5") + " -o " + Bad("x.h5") +
                    " --threads 10000",
                "hardware threads; using");
}

TEST_F(BadInputTest, EvaluateOnAShortDriveAndItsPlots) {
  // run_a's drive is about 40 m: no KITTI segment of 100 m, so t_rel and r_rel are undefined.
  ExpectQuiet("evaluate", "--gt " + kRun + "/data/poses/00.txt --est " + In("prior.h5") +
                              " --json " + Bad("short.json") + " --markdown " + Bad("short.md") +
                              " --plot-dir " + Bad("short_plots"));
  const auto report = nlohmann::json::parse(io::ReadTextFile(Bad("short.json")));
  const auto& kitti = report["estimates"][0]["kitti"];
  EXPECT_EQ(kitti["segments"], 0);
  EXPECT_TRUE(kitti["t_rel_percent"].is_null()) << kitti.dump();
  EXPECT_TRUE(kitti["r_rel_deg_per_100m"].is_null()) << kitti.dump();
  const std::string md = io::ReadTextFile(Bad("short.md"));
  EXPECT_NE(md.find("| n/a | n/a | 0 |"), std::string::npos) << md;
  EXPECT_NE(md.find("are n/a: its path is shorter than the shortest KITTI segment"),
            std::string::npos)
      << md;
  EXPECT_TRUE(io::FileExists(Bad("short_plots/kitti_per_length.png")));
  ExpectError("evaluate",
              "--gt " + kRun + "/data/poses/00.txt --est " + In("prior.h5") + " --plot-dir " +
                  Bad("plots_x") + " --python /nonexistent/python3",
              "--python /nonexistent/python3: not a Python interpreter with matplotlib");
  EXPECT_FALSE(io::FileExists(Bad("plots_x")));
}

}  // namespace
}  // namespace jvl
