// File helpers: atomic writes, whole-file reads, content hashes for provenance.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace jvl::io {

struct FileInfo {
  std::string path;
  int64_t size = 0;
  std::string hash;  // "fnv1a64:<16 hex>" of the content; for a folder, of its key files.
};

// Size and content hash of a file (throws jvl::Error naming the file if unreadable).
FileInfo DescribeFile(const std::string& path);
bool FileExists(const std::string& path);
// Whether two paths name the same file: the same device and inode when both exist (symbolic
// links, "./" and hard links are seen through), else the same normalised absolute path.
bool SameFile(const std::string& a, const std::string& b);
bool IsDirectory(const std::string& path);
int64_t FileSize(const std::string& path);  // -1 if missing.
std::string ReadTextFile(const std::string& path);

// Writes `path` atomically: `writer` receives a temporary path in the same folder; after it
// returns the temporary file is renamed over `path`. If `writer` throws, the temporary file is
// removed and `path` is untouched. Parent folders are created.
void AtomicWrite(const std::string& path, const std::function<void(const std::string&)>& writer);
// The temporary name AtomicWrite and H5Writer write `path` under: "<path>.tmp.<pid>".
std::string TempPathFor(const std::string& path);
void WriteTextFileAtomic(const std::string& path, const std::string& content);
void CreateDirectories(const std::string& dir);

// A temporary file being written: while the object lives, an interrupt (SIGINT, SIGTERM,
// SIGHUP; see InstallInterruptCleanup) removes the file before the process ends. SIGKILL
// cannot be caught: its temporary files stay behind (docs/robustness.md says how to find them).
class PendingTempFile {
 public:
  explicit PendingTempFile(const std::string& path);
  ~PendingTempFile();
  PendingTempFile(const PendingTempFile&) = delete;
  PendingTempFile& operator=(const PendingTempFile&) = delete;

 private:
  int slot_ = -1;
};

// Installs the handler of SIGINT, SIGTERM and SIGHUP that removes every PendingTempFile and
// then ends the process by the same signal (exit status 128 + signal in a shell). Idempotent.
void InstallInterruptCleanup();

}  // namespace jvl::io
