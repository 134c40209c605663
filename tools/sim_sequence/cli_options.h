// Command-line options of sim_sequence: the route, the sensors' noise and the world.
#pragma once

#include "app/tool.h"
#include "sim/sequence.h"

namespace jvl::tools {

void AddSimSequenceFlags(app::Tool& tool, sim::SequenceOptions* options);

}  // namespace jvl::tools
