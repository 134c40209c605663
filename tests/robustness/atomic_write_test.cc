// Atomic writes under a kill signal: a process killed while it writes an artifact leaves the
// previous artifact intact under the final name (and, after SIGKILL only, a "<name>.tmp.<pid>"
// file beside it: SIGINT, SIGTERM and SIGHUP are caught and the temporary file removed).
//
// The library cases stop the writer in the middle of its write and kill it there; the tool cases
// run the real command lines with pause_at_rename.c preloaded, which stops them at the rename of
// a finished temporary file, and kill them there: every kill lands inside a write, with no race.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

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
  // Without the tools' interrupt handler every signal leaves the temporary file; with it
  // (io::InstallInterruptCleanup, as every tool runs) SIGTERM and SIGINT remove it.
  for (const bool handler : {false, true}) {
    for (int sig : {SIGKILL, SIGTERM, SIGINT}) {
      const pid_t pid = KillInsideWrite(sig, [&](const std::function<void()>& stop) {
        if (handler) io::InstallInterruptCleanup();
        io::H5Writer w(path, "trajectory", 1);
        w.WriteArray<double>("trajectory/poses", std::vector<double>(7 * 200000, 1.0),
                             {200000, 7});
        stop();  // Killed here: poses written to the temporary file, frames not yet.
        w.WriteArray<int64_t>("trajectory/frames", std::vector<int64_t>(200000, 0));
        w.Commit(io::Provenance{});
      });
      EXPECT_TRUE(io::ReadTextFile(path) == before) << "signal " << sig;
      EXPECT_EQ(io::ReadTrajectory(path).size(), 10u);
      const std::string tmp = path + ".tmp." + std::to_string(pid);
      const bool removed = handler && sig != SIGKILL;
      EXPECT_EQ(io::FileExists(tmp), !removed) << "signal " << sig << ", handler " << handler;
      fs::remove(tmp);
    }
  }
}

TEST_F(AtomicWriteTest, InterruptedTextWriterRemovesItsTemporaryFile) {
  const std::string path = Path("poses.txt");
  io::WriteTrajectoryKitti(path, Line(10));
  const std::string before = io::ReadTextFile(path);
  for (int sig : {SIGTERM, SIGINT, SIGHUP}) {
    const pid_t pid = KillInsideWrite(sig, [&](const std::function<void()>& stop) {
      io::InstallInterruptCleanup();
      io::AtomicWrite(path, [&](const std::string& tmp) {
        std::ofstream out(tmp);
        out << io::FormatTrajectoryKitti(Line(5), false);
        out.flush();
        stop();
      });
    });
    EXPECT_TRUE(io::ReadTextFile(path) == before) << "signal " << sig;
    EXPECT_FALSE(io::FileExists(path + ".tmp." + std::to_string(pid))) << "signal " << sig;
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

// Runs argv in a child with pause_at_rename preloaded: the child stops at the rename() of a
// finished temporary file whose target contains `match` (any, if empty), with that temporary
// file complete on disk, and is killed there with `sig`. Returns the child's pid if it was
// killed at that point, -1 if it finished or failed before reaching it.
pid_t RunAndKillAtRename(const std::vector<std::string>& argv, int sig, const std::string& match) {
  int fds[2];
  if (::pipe(fds) != 0) return -1;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    ::setenv("LD_PRELOAD", JVL_PAUSE_AT_RENAME, 1);
    ::setenv("JVL_PAUSE_FD", std::to_string(fds[1]).c_str(), 1);
    if (!match.empty()) ::setenv("JVL_PAUSE_MATCH", match.c_str(), 1);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)) ::_exit(126);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  ::close(fds[1]);
  char byte = 0;
  const bool paused = ::read(fds[0], &byte, 1) == 1;  // 0: the child ended without pausing
  ::close(fds[0]);
  if (paused) ::kill(pid, sig);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return paused && WIFSIGNALED(status) && WTERMSIG(status) == sig ? pid : -1;
}

// Runs argv to the end; returns its exit status.
int RunToEnd(const std::vector<std::string>& argv) {
  std::string cmd;
  for (const auto& a : argv) cmd += "'" + a + "' ";
  return std::system((cmd + "> /dev/null 2>&1").c_str());
}

TEST_F(AtomicWriteTest, ToolKilledWhileWritingItsArtifactKeepsThePreviousOne) {
  const std::string seq = kRunA + "/data/sequences/00";
  if (!io::IsDirectory(seq)) GTEST_SKIP() << seq << " not found (robust_pipeline_a makes it)";
  const std::string out = Path("odom.h5");
  const std::vector<std::string> argv = {
      kBin + "lidar_odom", "--dataset", seq, "--frames", "0:8", "-o", out,
      "--quiet",           "--threads", "1"};
  ASSERT_EQ(RunToEnd(argv), 0);
  ASSERT_EQ(io::ReadTrajectory(out).size(), 8u);
  const std::string before = io::ReadTextFile(out);
  for (const int sig : {SIGKILL, SIGTERM, SIGINT}) {
    const pid_t pid = RunAndKillAtRename(argv, sig, "odom.h5");
    ASSERT_GT(pid, 0) << "signal " << sig << ": the run did not reach its rename";
    EXPECT_TRUE(io::ReadTextFile(out) == before) << "signal " << sig << ": artifact changed";
    EXPECT_EQ(io::ReadTrajectory(out).size(), 8u) << "signal " << sig;
    // SIGTERM and SIGINT are caught: the tool removes its temporary file before it ends.
    const std::string tmp = out + ".tmp." + std::to_string(pid);
    EXPECT_EQ(io::FileExists(tmp), sig == SIGKILL) << "signal " << sig;
    fs::remove(tmp);
  }
}

TEST_F(AtomicWriteTest, SimSequenceKilledMidRunLeavesOnlyCompleteFiles) {
  const std::string ref = Path("ref"), out = Path("out");
  auto argv = [&](const std::string& root) {
    return std::vector<std::string>{kBin + "sim_sequence", "-o", root, "--frames", "8", "--quiet",
                                    "--threads",           "1"};
  };
  ASSERT_EQ(RunToEnd(argv(ref)), 0);
  ASSERT_EQ(RunToEnd(argv(out)), 0);
  // Reruns over the finished output, killed at the rename of scan 3 (its new version complete in
  // the temporary file), by a signal the tool cannot catch and by one it does.
  for (const int sig : {SIGKILL, SIGTERM}) {
    const pid_t pid = RunAndKillAtRename(argv(out), sig, "velodyne/000003.bin");
    ASSERT_GT(pid, 0) << "signal " << sig << ": the run did not reach the rename of scan 3";
    int temporary = 0;
    for (const auto& e : fs::recursive_directory_iterator(out)) {
      if (!e.is_regular_file()) continue;
      const std::string rel = fs::relative(e.path(), out).string();
      if (rel.find(".tmp.") != std::string::npos) {
        ++temporary;
        fs::remove(e.path());
        continue;
      }
      if (rel.find("/sim/") != std::string::npos) continue;  // JSON: provenance times differ.
      // sim_sequence is deterministic: every file under a final name is the complete reference.
      EXPECT_TRUE(io::ReadTextFile(e.path().string()) == io::ReadTextFile(ref + "/" + rel))
          << rel << ", signal " << sig;
    }
    EXPECT_EQ(temporary, sig == SIGKILL ? 1 : 0) << "signal " << sig;
  }
}

}  // namespace
}  // namespace jvl
