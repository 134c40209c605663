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
bool IsDirectory(const std::string& path);
int64_t FileSize(const std::string& path);  // -1 if missing.
std::string ReadTextFile(const std::string& path);

// Writes `path` atomically: `writer` receives a temporary path in the same folder; after it
// returns the temporary file is renamed over `path`. If `writer` throws, the temporary file is
// removed and `path` is untouched. Parent folders are created.
void AtomicWrite(const std::string& path, const std::function<void(const std::string&)>& writer);
void WriteTextFileAtomic(const std::string& path, const std::string& content);
void CreateDirectories(const std::string& dir);

}  // namespace jvl::io
