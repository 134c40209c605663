// Command-line flags for every VisualMapOptions field (names and defaults in docs/visual_assoc.md).
#pragma once

#include <CLI/CLI.hpp>

#include "mapping/visual/map_builder.h"

namespace jvl::tools {

void AddVisualMapFlags(CLI::App& cli, mapping::VisualMapOptions* options);

}  // namespace jvl::tools
