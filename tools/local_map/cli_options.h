// Command-line options of local_map (method and solver groups).
#pragma once

#include <string>

#include "app/tool.h"
#include "mapping/local/local_mapping.h"

namespace jvl::tools {

// `vertical_correction`: auto or an angle, resolved by io::ResolveVerticalCorrection into
// scan->preprocess.
void AddLocalMapFlags(app::Tool& tool, mapping::LocalMappingOptions* options,
                      mapping::ScanOptions* scan, std::string* vertical_correction);

}  // namespace jvl::tools
