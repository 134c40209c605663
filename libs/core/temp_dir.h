// A fresh directory under the system's temporary directory, removed with everything in it when
// the object goes: for tests that write files. Unique per process and object, so that
// concurrent runs of a suite (two build trees, ctest -j) never share a file.
#pragma once

#include <filesystem>
#include <string>

namespace jvl {

class TempDir {
 public:
  // <temp>/<prefix>_<pid>_<n>, for the first n that does not exist yet.
  explicit TempDir(const std::string& prefix = "jvl");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // The path of `name` inside the directory.
  std::string Path(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace jvl
