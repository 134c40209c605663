#include "io/files.h"

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/check.h"
#include "core/hash.h"

namespace fs = std::filesystem;

namespace jvl::io {

bool FileExists(const std::string& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}

bool SameFile(const std::string& a, const std::string& b) {
  struct stat sa, sb;
  if (::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0)
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  std::error_code ec_a, ec_b;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a), ec_a);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b), ec_b);
  if (ec_a || ec_b) return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
  return ca == cb;
}

bool IsDirectory(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

int64_t FileSize(const std::string& path) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  return ec ? -1 : static_cast<int64_t>(size);
}

std::string ReadTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  JVL_CHECK(in.good(), path << ": cannot open file");
  // A regular file is read in one piece into a string of its size (a scan is read this way for
  // every frame of every stage); a stream of unknown length (a pipe, /dev/stdin) chunk by chunk.
  std::string bytes;
  struct stat st;
  if (::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    bytes.resize(static_cast<size_t>(st.st_size));
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    JVL_CHECK(!in.bad(), path << ": read error");
    bytes.resize(static_cast<size_t>(in.gcount()));  // Shorter if it shrank meanwhile.
    if (in.gcount() < st.st_size) return bytes;
  }
  char buffer[1 << 16];
  while (in.read(buffer, sizeof(buffer)) || in.gcount() > 0)
    bytes.append(buffer, static_cast<size_t>(in.gcount()));
  JVL_CHECK(!in.bad(), path << ": read error");
  return bytes;
}

FileInfo DescribeFile(const std::string& path) {
  FileInfo info;
  info.path = path;
  if (IsDirectory(path)) {
    info.size = 0;
    info.hash = "dir";
    return info;
  }
  std::ifstream in(path, std::ios::binary);
  JVL_CHECK(in.good(), path << ": cannot open file");
  Fnv1a64 hash;
  char buf[1 << 16];
  while (in) {
    in.read(buf, sizeof(buf));
    const auto n = in.gcount();
    if (n > 0) {
      hash.Update(buf, static_cast<size_t>(n));
      info.size += n;
    }
  }
  info.hash = "fnv1a64:" + hash.Hex();
  return info;
}

void CreateDirectories(const std::string& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  fs::create_directories(dir, ec);
  JVL_CHECK(!ec, dir << ": cannot create folder (" << ec.message() << ")");
}

namespace {

// Registry of the temporary files being written, readable from a signal handler: fixed slots,
// each claimed with a lock-free atomic and holding a NUL-terminated path.
constexpr int kTempSlots = 64;
constexpr size_t kTempPathMax = 4096;
struct TempSlot {
  std::atomic<int> state{0};  // 0 free, 1 being filled, 2 holds a path
  char path[kTempPathMax];
};
TempSlot g_temp_slots[kTempSlots];
static_assert(std::atomic<int>::is_always_lock_free, "signal handler needs lock-free atomics");

extern "C" void RemoveTempFilesAndDie(int sig) {
  for (TempSlot& slot : g_temp_slots)
    if (slot.state.load() == 2) ::unlink(slot.path);  // async-signal-safe
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

PendingTempFile::PendingTempFile(const std::string& path) {
  if (path.size() >= kTempPathMax) return;  // not cleaned on interrupt; still removed on error
  for (int i = 0; i < kTempSlots; ++i) {
    int expected = 0;
    if (!g_temp_slots[i].state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(g_temp_slots[i].path, path.c_str(), path.size() + 1);
    g_temp_slots[i].state.store(2);
    slot_ = i;
    return;
  }
}

PendingTempFile::~PendingTempFile() {
  if (slot_ >= 0) g_temp_slots[slot_].state.store(0);
}

void InstallInterruptCleanup() {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction action;
    std::memset(&action, 0, sizeof(action));
    action.sa_handler = RemoveTempFilesAndDie;
    sigemptyset(&action.sa_mask);
    ::sigaction(sig, &action, nullptr);
  }
}

std::string TempPathFor(const std::string& path) {
  // Same folder as the target so that rename() is atomic; the pid keeps parallel runs apart.
  return path + ".tmp." + std::to_string(::getpid());
}

void AtomicWrite(const std::string& path, const std::function<void(const std::string&)>& writer) {
  const fs::path final_path(path);
  if (final_path.has_parent_path()) CreateDirectories(final_path.parent_path().string());
  const std::string tmp = TempPathFor(path);
  const PendingTempFile pending(tmp);
  try {
    writer(tmp);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, final_path, ec);
  if (ec) {
    const std::string reason = ec.message();  // remove() below resets ec.
    fs::remove(tmp, ec);
    JVL_THROW(path << ": cannot move the finished file into place (" << reason << ")");
  }
}

void WriteTextFileAtomic(const std::string& path, const std::string& content) {
  AtomicWrite(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    JVL_CHECK(out.good(), tmp << ": cannot open for writing");
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    JVL_CHECK(out.good(), tmp << ": write failed (disk full?)");
  });
}

}  // namespace jvl::io
