// Command-line options of vp_detect: the line detector and the VP estimation.
#pragma once

#include <string>

#include "app/tool.h"
#include "vp_detect_run.h"

namespace jvl::tools {

// `detector` takes the detector's name (fld, lsd), parsed by the caller.
void AddVpDetectFlags(app::Tool& tool, VpDetectRunOptions* run, std::string* detector);

}  // namespace jvl::tools
