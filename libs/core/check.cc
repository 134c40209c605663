#include "core/check.h"

#include <cstring>

namespace jvl {
namespace {

std::string ShortFile(const char* file) {
  // Keep "libs/<domain>/<file>" so the location is readable but still precise.
  std::string path(file);
  const auto pos = path.find("/libs/");
  if (pos != std::string::npos) return path.substr(pos + 6);
  const auto tools = path.find("/tools/");
  if (tools != std::string::npos) return path.substr(tools + 1);
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

Error::Error(const std::string& message, const char* file, int line)
    : std::runtime_error(message + " [" + ShortFile(file) + ":" + std::to_string(line) + "]"),
      message_(message) {}

void ThrowError(const std::string& message, const char* file, int line) {
  throw Error(message, file, line);
}

}  // namespace jvl
