#include "core/temp_dir.h"

#include <unistd.h>

#include <atomic>
#include <system_error>

#include "core/check.h"

namespace jvl {

TempDir::TempDir(const std::string& prefix) {
  static std::atomic<int> next{0};
  const std::filesystem::path base = std::filesystem::temp_directory_path();
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const std::filesystem::path p =
        base / (prefix + "_" + std::to_string(::getpid()) + "_" + std::to_string(next++));
    std::error_code ec;
    if (std::filesystem::create_directory(p, ec)) {
      path_ = p;
      return;
    }
    JVL_CHECK(!ec || std::filesystem::exists(p),
              "cannot create the directory " << p.string() << ": " << ec.message());
  }
  JVL_THROW("no free temporary directory name for prefix '" << prefix << "'");
}

TempDir::~TempDir() {
  std::error_code ec;  // Never throws: a directory left behind is only untidy.
  std::filesystem::remove_all(path_, ec);
}

}  // namespace jvl
