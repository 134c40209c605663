// Command-line options of local_map (method and solver groups).
#pragma once

#include <CLI/CLI.hpp>

#include "mapping/local/local_mapping.h"

namespace jvl::tools {

void AddLocalMapFlags(CLI::App& cli, mapping::LocalMappingOptions* options,
                      mapping::ScanOptions* scan);

}  // namespace jvl::tools
