// Atomic writes under a kill signal: a process killed while it writes an artifact leaves the
// previous artifact intact under the final name (and at most a "<name>.tmp.<pid>" file beside it).
//
// The library cases stop the writer in the middle of its write and kill it there; the tool cases
// run the real command lines and kill them the moment their temporary file appears.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>

#include "io/artifact.h"
#include "io/files.h"
#include "io/trajectory_io.h"

namespace jvl {
namespace {

namespace fs = std::filesystem;

const std::string kBin = std::string(JVL_BINARY_DIR) + "/bin/";
const std::string kRunA = std::string(JVL_BINARY_DIR) + "/tests/robustness/run_a";

class AtomicWriteTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(JVL_BINARY_DIR) / "tests/robustness/atomic" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

Trajectory Line(int n) {
  Trajectory t;
  for (int i = 0; i < n; ++i) t.Append(i, Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, 0.5 * i}));
  return t;
}

// Forks; the child runs `write` and calls `stop()` halfway, which tells the parent and waits to
// be killed. The parent kills it with `sig` there. Returns the child's pid.
pid_t KillInsideWrite(int sig, const std::function<void(const std::function<void()>&)>& write) {
  int fds[2];
  EXPECT_EQ(::pipe(fds), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    write([&] {
      const char c = 'x';
      if (::write(fds[1], &c, 1) != 1) ::_exit(3);
      while (true) ::pause();
    });
    ::_exit(0);  // Not reached when the parent kills in time.
  }
  ::close(fds[1]);
  char c = 0;
  EXPECT_EQ(::read(fds[0], &c, 1), 1) << "the writer never reached the middle of its write";
  ::close(fds[0]);
  ::kill(pid, sig);
  int status = 0;
  ::waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig);
  return pid;
}

TEST_F(AtomicWriteTest, KilledHdf5WriterLeavesThePreviousArtifact) {
  const std::string path = Path("odom.h5");
  io::WriteTrajectoryArtifact(path, Line(10), io::Provenance{});
  const std::string before = io::ReadTextFile(path);
  for (int sig : {SIGKILL, SIGTERM, SIGINT}) {
    const pid_t pid = KillInsideWrite(sig, [&](const std::function<void()>& stop) {
      io::H5Writer w(path, "trajectory", 1);
      w.WriteArray<double>("trajectory/poses", std::vector<double>(7 * 200000, 1.0), {200000, 7});
      stop();  // Killed here: poses written to the temporary file, frames not yet.
      w.WriteArray<int64_t>("trajectory/frames", std::vector<int64_t>(200000, 0));
      w.Commit(io::Provenance{});
    });
    EXPECT_TRUE(io::ReadTextFile(path) == before) << "signal " << sig;
    EXPECT_EQ(io::ReadTrajectory(path).size(), 10u);
    const std::string tmp = path + ".tmp." + std::to_string(pid);
    EXPECT_TRUE(io::FileExists(tmp)) << "the interrupted write happened elsewhere";
    fs::remove(tmp);
  }
}

TEST_F(AtomicWriteTest, KilledTextWriterLeavesThePreviousFile) {
  const std::string path = Path("poses.txt");
  io::WriteTrajectoryKitti(path, Line(10));
  const std::string before = io::ReadTextFile(path);
  const pid_t pid = KillInsideWrite(SIGKILL, [&](const std::function<void()>& stop) {
    io::AtomicWrite(path, [&](const std::string& tmp) {
      std::ofstream out(tmp);
      out << io::FormatTrajectoryKitti(Line(5), false);
      out.flush();
      stop();  // Half of the new content is on disk.
      out << io::FormatTrajectoryKitti(Line(5), false);
    });
  });
  EXPECT_TRUE(io::ReadTextFile(path) == before);
  EXPECT_GT(io::FileSize(path + ".tmp." + std::to_string(pid)), 0);
}

// Runs argv in a child; kills it with `sig` as soon as one of `watched(pid)` exists. Returns
// true if the kill happened while that file existed (the child was inside that write).
bool RunAndKillWhenFileAppears(const std::vector<std::string>& argv, int sig,
                               const std::function<std::vector<std::string>(pid_t)>& watched) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)) ::_exit(126);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  const std::vector<std::string> paths = watched(pid);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  bool killed_inside = false;
  int status = 0;
  while (!killed_inside && std::chrono::steady_clock::now() < deadline) {
    for (const std::string& path : paths) {
      struct stat st;
      if (::stat(path.c_str(), &st) == 0) {
        ::kill(pid, sig);
        killed_inside = true;
        break;
      }
    }
    if (!killed_inside && ::waitpid(pid, &status, WNOHANG) == pid) return false;  // Finished.
  }
  if (!killed_inside) ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  return killed_inside && WIFSIGNALED(status);
}

TEST_F(AtomicWriteTest, ToolKilledWhileWritingItsArtifactKeepsThePreviousOne) {
  const std::string seq = kRunA + "/data/sequences/00";
  if (!io::IsDirectory(seq)) GTEST_SKIP() << seq << " not found (robust_pipeline_a makes it)";
  const std::string out = Path("odom.h5");
  const std::vector<std::string> argv = {
      kBin + "lidar_odom", "--dataset", seq, "--frames", "0:8", "-o", out,
      "--quiet",           "--threads", "1"};
  ASSERT_FALSE(
      RunAndKillWhenFileAppears(argv, SIGKILL, [](pid_t) { return std::vector<std::string>{}; }));
  ASSERT_EQ(io::ReadTrajectory(out).size(), 8u);
  // The kill comes while the temporary file exists; on a busy machine the write can also finish
  // first, then the new complete artifact is the previous one of the next attempt.
  int inside = 0;
  for (int attempt = 0; attempt < 12 && inside < 2; ++attempt) {
    const std::string before = io::ReadTextFile(out);
    const int sig = attempt % 2 == 0 ? SIGKILL : SIGTERM;
    pid_t child = 0;
    const bool killed = RunAndKillWhenFileAppears(argv, sig, [&](pid_t pid) {
      child = pid;
      return std::vector<std::string>{out + ".tmp." + std::to_string(pid)};
    });
    if (killed) {
      ++inside;
      EXPECT_TRUE(io::ReadTextFile(out) == before) << "attempt " << attempt << ": artifact changed";
    }
    EXPECT_EQ(io::ReadTrajectory(out).size(), 8u) << "attempt " << attempt;
    fs::remove(out + ".tmp." + std::to_string(child));
  }
  RecordProperty("killed_while_writing", inside);
  EXPECT_GE(inside, 1) << "no run was killed while its artifact was being written";
}

TEST_F(AtomicWriteTest, SimSequenceKilledMidRunLeavesOnlyCompleteFiles) {
  const std::string ref = Path("ref"), out = Path("out");
  auto argv = [&](const std::string& root) {
    return std::vector<std::string>{kBin + "sim_sequence", "-o", root, "--frames", "8", "--quiet",
                                    "--threads",           "1"};
  };
  auto never = [](pid_t) { return std::vector<std::string>{}; };
  ASSERT_FALSE(RunAndKillWhenFileAppears(argv(ref), SIGKILL, never));
  ASSERT_FALSE(RunAndKillWhenFileAppears(argv(out), SIGKILL, never));
  // Reruns over the finished output, killed while one of the scans is being written.
  int inside = 0;
  for (int attempt = 0; attempt < 3 && inside < 1; ++attempt) {
    const bool killed = RunAndKillWhenFileAppears(argv(out), SIGKILL, [&](pid_t pid) {
      std::vector<std::string> tmp;
      for (int f = 1; f < 8; ++f) {
        char name[64];
        std::snprintf(name, sizeof(name), "/sequences/00/velodyne/%06d.bin.tmp.%d", f, pid);
        tmp.push_back(out + name);
      }
      return tmp;
    });
    inside += killed ? 1 : 0;
    for (const auto& e : fs::recursive_directory_iterator(out)) {
      if (!e.is_regular_file()) continue;
      const std::string rel = fs::relative(e.path(), out).string();
      if (rel.find(".tmp.") != std::string::npos) {
        EXPECT_TRUE(killed) << rel << " left by a run that was not killed";
        fs::remove(e.path());
        continue;
      }
      if (rel.find("/sim/") != std::string::npos) continue;  // JSON: provenance times differ.
      // sim_sequence is deterministic: every file under a final name is the complete reference.
      EXPECT_TRUE(io::ReadTextFile(e.path().string()) == io::ReadTextFile(ref + "/" + rel)) << rel;
    }
  }
  RecordProperty("killed_while_writing", inside);
  EXPECT_GE(inside, 1) << "no run was killed while a scan was being written";
}

}  // namespace
}  // namespace jvl
