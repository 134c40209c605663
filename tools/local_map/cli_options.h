// Command-line options of local_map (method and solver groups).
#pragma once

#include "app/tool.h"
#include "mapping/local/local_mapping.h"

namespace jvl::tools {

void AddLocalMapFlags(app::Tool& tool, mapping::LocalMappingOptions* options,
                      mapping::ScanOptions* scan);

}  // namespace jvl::tools
