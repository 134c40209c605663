// Command-line flags for every VisualMapOptions field (names and defaults in docs/visual_assoc.md).
#pragma once

#include "app/tool.h"
#include "mapping/visual/map_builder.h"

namespace jvl::tools {

void AddVisualMapFlags(app::Tool& tool, mapping::VisualMapOptions* options);

}  // namespace jvl::tools
