// Logging set-up shared by all tools: spdlog to stderr, level from --log-level.
#pragma once

#include <string>

namespace jvl {

// Valid levels: trace, debug, info, warn, error, off. Throws jvl::Error on anything else.
void SetupLogging(const std::string& level);

}  // namespace jvl
