#include "core/logging.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "core/check.h"

namespace jvl {

void SetupLogging(const std::string& level) {
  const spdlog::level::level_enum parsed = spdlog::level::from_str(level);
  // from_str maps unknown names to "off"; only accept "off" when asked for.
  JVL_CHECK(parsed != spdlog::level::off || level == "off",
            "--log-level: unknown level '" << level << "' (trace, debug, info, warn, error, off)");
  spdlog::drop("jvl");  // a second call (a second tool run in one process) replaces it
  auto logger = spdlog::stderr_color_mt("jvl");
  logger->set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
  logger->set_level(parsed);
  spdlog::set_default_logger(logger);
}

}  // namespace jvl
