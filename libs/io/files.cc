#include "io/files.h"

#include <unistd.h>

#include <cstdio>
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
  std::ostringstream ss;
  ss << in.rdbuf();
  JVL_CHECK(!in.bad(), path << ": read error");
  return ss.str();
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

void AtomicWrite(const std::string& path, const std::function<void(const std::string&)>& writer) {
  const fs::path final_path(path);
  if (final_path.has_parent_path()) CreateDirectories(final_path.parent_path().string());
  // Same folder as the target so that rename() is atomic; the pid keeps parallel runs apart.
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
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
